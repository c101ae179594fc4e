# The unix port with the core frozen: what the port's standard variant freezes (asyncio), then
# the core (core.py gives the metadata).
include("$(MPY_DIR)/extmod/asyncio")
include("core.py")
