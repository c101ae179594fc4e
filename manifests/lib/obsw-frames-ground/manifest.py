metadata(
    version="0.1.0", description="the ground side of the links: FOP-1 and the TM demultiplexer"
)

require("obsw-frames", library="obsw")

package(
    "obsw/frames",
    files=["fop.py", "fop_table.py", "sync.py", "tm_demux.py", "viterbi.py"],
    base_path="../../../micropython",
)
