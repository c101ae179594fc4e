metadata(
    version="0.1.0",
    description="SpaceCAN master: controller, clients, equipment components, device access",
)

require("obsw-spacecan-node", library="obsw")
require("obsw-il", library="obsw")

package(
    "obsw/spacecan",
    files=[
        "client.py",
        "controller.py",
        "device_access.py",
        "equipment.py",
        "master.py",
        "requests.py",
        "sim.py",
    ],
    base_path="../../../micropython",
)
