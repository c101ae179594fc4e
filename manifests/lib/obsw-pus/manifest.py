metadata(
    version="0.1.0",
    description="PUS-C: packets, field types, the application process, services 1-23",
)

require("obsw-il", library="obsw")
require("obsw-util", library="obsw")
require("obsw-cfdp", library="obsw")
require("obsw-pluto", library="obsw")

package("obsw/pus", base_path="../../../micropython")
