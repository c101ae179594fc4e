metadata(
    version="0.1.0", description="CFDP (CCSDS 727.0-B-5): PDUs, entity, procedures, filestore"
)

require("obsw-base", library="obsw")
require("obsw-il", library="obsw")

package("obsw/cfdp", base_path="../../../micropython")
