metadata(
    version="0.1.0",
    description="SpaceCAN as a node: responder, redundancy, fragments, sync and time",
)

require("obsw-base", library="obsw")

package(
    "obsw/spacecan",
    files=[
        "__init__.py",
        "encoding.py",
        "events.py",
        "fragment.py",
        "ids.py",
        "nodedef.py",
        "packets.py",
        "redundancy.py",
        "responder.py",
        "timeframes.py",
    ],
    base_path="../../../micropython",
)
