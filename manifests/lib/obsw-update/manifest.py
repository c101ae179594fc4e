metadata(
    version="0.1.0",
    description="signed software update packages: the format, its reader, Ed25519 and SHA-512",
)

require("obsw-base", library="obsw")

package(
    "obsw/update",
    files=["__init__.py", "ed25519.py", "package.py", "sha512.py", "signature.py"],
    base_path="../../../micropython",
)
