# The shared obsw core, frozen as bytecode into every board image: every package of the core,
# each with its own manifest under lib/ (micropython-lib style: metadata, require, package).
# A mission's image requires the core the same way and adds its own modules (docs/topology.md).
metadata(version="0.1.0", description="obsw shared core (PUS, CFDP, frames, SpaceCAN, IL, PLUTO)")

add_library("obsw", "lib")
require("obsw", library="obsw")
