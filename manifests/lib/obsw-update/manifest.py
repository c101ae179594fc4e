metadata(version="0.1.0", description="signed software update packages: the format and its reader")

require("obsw-base", library="obsw")

package(
    "obsw/update",
    files=["__init__.py", "package.py"],
    base_path="../../../micropython",
)
