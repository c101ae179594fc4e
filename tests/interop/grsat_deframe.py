"""Run by Debian's python3 (GNU Radio 3.10 and gr-satellites): deframe a file of float32 soft
symbols (positive: 1), repeated, with gr-satellites' own CCSDS deframer and print the first
EXPECTED_FRAMES frames in hex (or what came within 120 s, or before none came for 5 s).

grsat_deframe.py SYMBOLS_FILE rs|concatenated FRAME_SIZE INTERLEAVING EXPECTED_FRAMES
"""

import sys
import time

import numpy as np
import pmt
from gnuradio import blocks, gr

# gr-satellites 4.4 names the PDU item type blocks.byte_t, which GNU Radio 3.10 keeps as
# gr.types.byte_t: give blocks that name.
if not hasattr(blocks, "byte_t"):
    blocks.byte_t = gr.types.byte_t
from satellites.components.deframers.ccsds_concatenated_deframer import (
    ccsds_concatenated_deframer,
)
from satellites.components.deframers.ccsds_rs_deframer import ccsds_rs_deframer


def main(path, kind, frame_size, depth, expect):
    soft = np.fromfile(path, dtype=np.float32)
    tb = gr.top_block()
    # the symbols repeat: a flowgraph whose source ends shuts its message ports down and drops
    # the PDUs still on their way, so the stream never ends and we stop at ``expect`` frames
    src = blocks.vector_source_f(soft.tolist(), True)
    cls = ccsds_rs_deframer if kind == "rs" else ccsds_concatenated_deframer
    deframer = cls(frame_size=frame_size, rs_interleaving=depth, syncword_threshold=4)
    sink = blocks.message_debug()
    tb.connect(src, deframer)
    tb.msg_connect((deframer, "out"), (sink, "store"))
    tb.start()
    deadline = time.monotonic() + 120
    last, since = -1, time.monotonic()
    while time.monotonic() < deadline and sink.num_messages() < expect:
        if sink.num_messages() != last:
            last, since = sink.num_messages(), time.monotonic()
        elif time.monotonic() - since > 5:
            break
        time.sleep(0.05)
    tb.stop()
    tb.wait()
    for i in range(min(expect, sink.num_messages())):
        msg = sink.get_message(i)
        print("FRAME", bytes(pmt.u8vector_elements(pmt.cdr(msg))).hex())


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5]))
