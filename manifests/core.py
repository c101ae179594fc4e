# The shared obsw core, frozen as bytecode into every board image.
metadata(version="0.1.0", description="obsw shared core (PUS, CFDP, frames, SpaceCAN, IL, PLUTO)")

package("obsw", base_path="../micropython")
