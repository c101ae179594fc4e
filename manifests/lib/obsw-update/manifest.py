metadata(version="0.1.0", description="software update: Ed25519 signature verification, SHA-512")

require("obsw-base", library="obsw")

package(
    "obsw/update",
    files=["__init__.py", "ed25519.py", "sha512.py", "signature.py"],
    base_path="../../../micropython",
)
