# The unix port with the core frozen: what the port's standard variant freezes (asyncio), then
# the core, as core.py freezes it.
metadata(version="0.1.0", description="obsw core frozen into the MicroPython unix port")

include("$(MPY_DIR)/extmod/asyncio")
add_library("obsw", "lib")
require("obsw", library="obsw")
