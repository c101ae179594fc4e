"""Run inside the MicroPython unix port: the whole reconfiguration application on the in-memory
hardware layer for a long simulated run, printing the heap after each block of steps."""

import gc
import sys

from obsw.frames import cltu, tc
from obsw.reconfig.app import ReconfigApp
from obsw.reconfig.essential import HPC_POWER_CYCLE, Hpc
from obsw.reconfig.models import ModelHal

blocks = int(sys.argv[1]) if len(sys.argv) > 1 else 10
hal = ModelHal(rtc_seconds=21550 * 86400)
gc.collect()
base = gc.mem_free()
app = ReconfigApp(hal)
hpc = cltu.encode(
    tc.TcFrame(
        0x42, 0, tc.Segment(63, Hpc(HPC_POWER_CYCLE, (2, 100)).packet()).pack(), 0, True
    ).pack()
)
for b in range(blocks):
    for i in range(2000):
        if i == 1000:
            hal.uart_rx[0].extend(hpc)  # an HPC in every block: frames, CPDU, HPTM
        hal.idle(app.step())
        hal.uart_tx[0] = bytearray()
        hal.can_tx = []
    gc.collect()
    print("heap", b, base - gc.mem_free())
print("steps", app.counters["steps"], "errors", app.counters["loop_errors"])
print("hpcs", app.essential.counters["hpcs"], "kicks", hal.kick_count)
