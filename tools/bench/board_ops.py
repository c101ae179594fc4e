"""The operations tools/bench/board.py counts, run by the MicroPython interpreter under test.

    micropython board_ops.py OP N      set up, then run operation OP N times; prints a check line
    micropython board_ops.py --list    the operation names

Everything before the timed loop (imports, the application's boot, the inputs) is the same
whatever N is (every case imports every module, so every collection marks the same heap), so
the instructions of one operation are the difference between two runs with
different N divided by the difference of N. Every counted operation starts on a freshly
collected heap (the collection is counted by the `gc_collect` case and subtracted), so its count
includes sweeping its own garbage, and the same operation costs the same whatever N is. `alloc`
after the check line is the heap allocated per operation: gc.mem_alloc() around a few
operations with the collector off, so nothing is freed meanwhile (the same few whatever N is).
"""

import gc
import sys

from obsw.frames import cltu, tc
from obsw.pluto.interp import Procedure, load
from obsw.pluto.system import SimulatedSystem
from obsw.pus.tc import PusTc
from obsw.pus.tm import PusTm
from obsw.reconfig.app import RECORD_CONTEXT, ReconfigApp
from obsw.reconfig.essential import HPC_LINES, TARGET_BOTH, Hpc
from obsw.reconfig.models import ModelHal
from obsw.reconfig.node import NODE_NOMINAL, definition
from obsw.spacecan.controller import Controller

SCID = 0x42
RTC_2025 = 20089 * 86400  # 2025-01-01 in seconds since 1970


class Rig:
    """The reconfiguration application after its boot, and a SpaceCAN controller for frames."""

    def __init__(self):
        self.hal = ModelHal(rtc_seconds=RTC_2025)  # its clock moves 5 us per reading
        self.app = ReconfigApp(self.hal)
        self.ctrl = Controller(heartbeat_period=0.5)
        self.ctrl.add_node(NODE_NOMINAL, definition(NODE_NOMINAL))
        self.ctrl.start(0.0)
        self.hal.idle(self.app.step())  # boot: safeguard records, watchdog, responder
        self.ctrl.take_frames()
        self.hal.can_tx = []
        self.hal.uart_tx[0] = bytearray()
        self.now = self.hal.now / 1000000

    def frames(self, make):
        """The frames the controller sends for ``make(ctrl, now)``."""
        make(self.ctrl, self.now)
        out = [(bus, can_id, bytes(data)) for bus, can_id, data in self.ctrl.take_frames()]
        if not out:
            raise RuntimeError("the controller sent nothing")
        return out


def _frame_op(rig, make):
    frames = rig.frames(make)
    hal = rig.hal
    rx = hal.can_rx
    can = rig.app._can
    now = rig.now

    def op():
        for bus, can_id, data in frames:
            rx[bus].append((can_id, data))
        can(now)
        hal.can_tx = []

    return op


def heartbeat(ctrl, now):
    ctrl._send_heartbeat(now)


def sync(ctrl, now):
    ctrl.send_sync(now)


def telecommand(ctrl, now):
    ctrl.request_parameters(NODE_NOMINAL, [1], now)  # TC[20,1]: report the CPDU state bits


def ping(ctrl, now):
    ctrl.request(NODE_NOMINAL, 17, 1, b"", now)


def _can_idle(rig):
    can = rig.app._can
    now = rig.now

    def op():
        can(now)

    return op


def _loop_idle(rig):
    step = rig.app.step

    def op():
        step()

    return op


def _loop_busy(rig):
    # a pass that does everything that can fall due together: status refresh, essential
    # report, state save, and one of each SpaceCAN frame kind on the bus
    app = rig.app
    hal = rig.hal
    frames = []
    for make in (heartbeat, sync, telecommand, ping):
        frames += rig.frames(make)
    rx = hal.can_rx

    def op():
        for bus, can_id, data in frames:
            rx[bus].append((can_id, data))
        app._next_status = 0
        app._next_report = 0
        app._next_save = 0
        app._dirty = True
        app.step()
        hal.can_tx = []
        hal.uart_tx[0] = bytearray()

    return op


def _essential(rig):
    app = rig.app
    hal = rig.hal
    values = []
    for i, value in enumerate((0x0A0, 0x050)):
        hpc = Hpc(HPC_LINES, (0x0F0, value), TARGET_BOTH)
        frame = tc.TcFrame(SCID, 0, tc.Segment(63, hpc.packet()).pack(), i, bypass=True)
        values.append(cltu.encode(frame.pack()))
    state = [0]

    def op():
        k = state[0]
        state[0] = k ^ 1
        hal.uart_rx[0].extend(values[k])  # alternate, so every HPC changes the lines
        app.step()
        hal.uart_tx[0] = bytearray()
        hal.can_tx = []

    return op


def _sgm_write(rig):
    sgm = rig.app.sgm
    payload = b"\x00\x01\x02\x03"

    def op():
        sgm.write(RECORD_CONTEXT, payload)

    return op


def _sgm_read(rig):
    sgm = rig.app.sgm
    sgm.write(RECORD_CONTEXT, b"\x00\x01\x02\x03")

    def op():
        sgm.read(RECORD_CONTEXT)

    return op


def _pus_tc_decode(rig):
    raw = PusTc(0x65, 17, 1, b"", 7).pack()
    unpack = PusTc.unpack

    def op():
        unpack(raw)

    return op


def _pus_tm_encode(rig):
    data = bytes(range(16))

    def op():
        PusTm(0x65, 3, 25, data, 7, 1, 0, (1000, 0)).pack()

    return op


PLUTO = """procedure
  initiate and confirm step Count
    declare variable i of type signed integer end declare
    main
      i := 0;
      while i < 1000000000 do
        i := i + 1;
      end while;
    end main
  end step;
end procedure
"""


def _pluto(rig):
    # one statement per operation (Procedure.step: the loop's `i := i + 1;` or its test)
    p = Procedure(load(PLUTO), SimulatedSystem({}))
    p.start(0)
    step = p.step

    def op():
        step(0)

    return op


def _gc_collect(rig):
    # the collections alone: run() collects before every operation
    def op():
        pass

    return op


def _empty(rig):
    def op():
        pass

    return op


OPS = {
    "empty": _empty,
    "gc_collect": _gc_collect,
    "frame_heartbeat": lambda rig: _frame_op(rig, heartbeat),
    "frame_sync": lambda rig: _frame_op(rig, sync),
    "frame_tc_20_1": lambda rig: _frame_op(rig, telecommand),
    "frame_ping_17_1": lambda rig: _frame_op(rig, ping),
    "can_idle": _can_idle,
    "loop_idle": _loop_idle,
    "loop_busy": _loop_busy,
    "essential_tc": _essential,
    "sgm_write": _sgm_write,
    "sgm_read": _sgm_read,
    "pus_tc_decode": _pus_tc_decode,
    "pus_tm_encode": _pus_tm_encode,
    "pluto_statement": _pluto,
}


ALLOC_OPS = 8  # operations measured for their allocations, gc off (the same for any N)


def run(name, n):
    rig = Rig()
    op = OPS[name](rig)
    op()  # first use: anything created lazily exists before counting starts
    gc.collect()
    gc.disable()
    before = gc.mem_alloc() if hasattr(gc, "mem_alloc") else 0
    for _ in range(ALLOC_OPS):
        op()
    after = gc.mem_alloc() if hasattr(gc, "mem_alloc") else 0
    gc.enable()
    collect = gc.collect
    if name == "gc_collect":
        for _ in range(n):
            collect()
    elif name == "empty":
        for _ in range(n):
            op()
    else:
        for _ in range(n):
            collect()  # the same heap before every operation: counted apart (gc_collect)
            op()
    gc.enable()
    app = rig.app
    print(
        "ok",
        name,
        n,
        "steps",
        app.counters["steps"],
        "errors",
        app.counters["loop_errors"],
        "hpcs",
        app.essential.counters["hpcs"],
        "bits",
        app.bits,
    )
    print("alloc", (after - before) // ALLOC_OPS)


if __name__ == "__main__":
    if sys.argv[1:] == ["--list"]:
        print(" ".join(OPS))
    else:
        run(sys.argv[1], int(sys.argv[2]))
