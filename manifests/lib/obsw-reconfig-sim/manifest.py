metadata(version="0.1.0", description="host models of the reconfiguration module's hardware")

require("obsw-reconfig", library="obsw")

package(
    "obsw/reconfig",
    files=["dekker_sim.py", "models.py"],
    base_path="../../../micropython",
)
