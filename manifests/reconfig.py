# The reconfiguration module's image: its application and only the core packages it needs.
# Every module that the entry point (boards/OBSW_RECONFIG/reconfig_main.py) imports, directly or
# not, must be frozen: tests/host/test_manifests.py and the firmware stage check it
# (`tools/mpy.py closure manifests/reconfig.py boards/OBSW_RECONFIG/reconfig_main.py`).
metadata(
    version="0.1.0",
    description="obsw reconfiguration module (CPDU, safeguard memory, time, essential TC/TM)",
)

add_library("obsw", "lib")
require("obsw-reconfig", library="obsw")  # with obsw-base, obsw-frames, obsw-spacecan-node

# the Pyboard hardware layer
module("hal_pyb.py", base_path="../boards/common")
module("reconfig_main.py", base_path="../boards/OBSW_RECONFIG")
