"""The operations tools/bench/board.py counts, run on the QEMU Cortex-M board (frozen core).

    import board_ops; board_ops.run("frame_heartbeat", 16)   # prints the case's figures

Each operation is timed on its own: the heap is collected first (outside the count), then the
CMSDK APB timer 0 of the MPS2 board (25 MHz, free-running down from 2**30 - 1, so its reading
is a small int and reading it allocates nothing) is read before and after the operation, with
the SysTick interrupt masked so that nothing else runs in between. Under QEMU's
`-icount shift=7` every guest instruction advances the virtual clock by 128 ns, 3.2 timer
ticks, so the tick difference fixes the instruction count exactly (board.py converts it and
subtracts the empty case, the timer reads themselves).

Printed, after all counting (printing meanwhile would wait on the UART):
    ticks NAME t1 t2 ...      the timer ticks of each operation
    alloc NAME BYTES          bytes allocated per operation (gc.mem_alloc around each of a few,
                              the collector off; the board's GC allocates in 16-byte blocks)
    heap NAME FREE            gc.mem_free() after a collection, with the case set up
    ok NAME ...               a check line (steps, errors, HPCs, CPDU bits of the application)

Frames reach the application through a hardware layer whose CAN side hands over a prepared
frame and counts what is sent (``Feed``): it allocates nothing, so a frame's figure is the
core's (a Pyboard's pyb.CAN recv and send come on top).
"""

import gc

import machine

import micropython

# Each case imports what it needs (a case runs after a soft reset): the whole core imported
# at once would not leave a Pyboard's heap room for the application.

SCID = 0x42
RTC_2025 = 20089 * 86400  # 2025-01-01 in seconds since 1970
EEPROM = 2048  # bytes per modelled EEPROM: room for the records, within a Pyboard's heap

_mem = machine.mem32
_TIMER = 0x40000000  # CMSDK APB timer 0 (mps2-an385): CTRL, VALUE, RELOAD
_VALUE = 0x40000004
_TOP = 0x3FFFFFFF  # a small int on a 32-bit port: reading it allocates nothing
_SYST_CSR = 0xE000E010
_TICKINT = 2


class Feed:
    """A hardware layer's CAN side that hands over queued frames and allocates nothing."""

    def __init__(self, hal):
        self.rx = [[], []]
        self.pos = [0, 0]
        self.sent = 0
        hal.can_recv = self.recv
        hal.can_send = self.send

    def load(self, frames):
        """``frames``: (bus, can_id, data); each bus gets its own in order."""
        for bus, can_id, data in frames:
            self.rx[bus].append((can_id, data))

    def rewind(self):
        self.pos[0] = 0
        self.pos[1] = 0

    @micropython.native  # a stand-in for the CAN driver, which is C on a board
    def recv(self, bus):
        i = self.pos[bus]
        q = self.rx[bus]
        if i >= len(q):
            return None
        self.pos[bus] = i + 1
        return q[i]

    @micropython.native
    def send(self, bus, can_id, data):
        self.sent += 1
        return True


class Rig:
    """The reconfiguration application after its boot, and a SpaceCAN controller for frames."""

    def __init__(self):
        from obsw.reconfig.app import ReconfigApp
        from obsw.reconfig.models import ModelHal
        from obsw.reconfig.node import NODE_NOMINAL, definition
        from obsw.spacecan.controller import Controller

        self.hal = ModelHal(rtc_seconds=RTC_2025, eeprom_size=EEPROM)
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
        if make is other_node:
            return make(self.ctrl, self.now)
        make(self.ctrl, self.now)
        out = [(bus, can_id, bytes(data)) for bus, can_id, data in self.ctrl.take_frames()]
        if not out:
            raise RuntimeError("the controller sent nothing")
        return out


def heartbeat(ctrl, now):
    ctrl._send_heartbeat(now)


def sync(ctrl, now):
    ctrl.send_sync(now)


def telecommand(ctrl, now):
    from obsw.reconfig.node import NODE_NOMINAL

    ctrl.request_parameters(NODE_NOMINAL, [1], now)  # TC[20,1]: report the CPDU state bits


def ping(ctrl, now):
    from obsw.reconfig.node import NODE_NOMINAL

    ctrl.request(NODE_NOMINAL, 17, 1, b"", now)


def other_node(ctrl, now):
    # a ping to node 11 (another responder): this node only has to see that it is not its own
    return [(0, 0x280 + 11, b"\x00\x00\x11\x01")]


def _frame_op(rig, make):
    # one SpaceCAN poll of the application that receives this frame (every fragment of a
    # request) and sends the replies
    feed = Feed(rig.hal)
    feed.load(rig.frames(make))
    can = rig.app._can
    now = rig.now
    rewind = feed.rewind

    def op():
        rewind()
        can(now)

    return op


def _frames_op(rig, make, k):
    # a poll that receives k frames of a kind back to back (a bus at full load)
    feed = Feed(rig.hal)
    frames = rig.frames(make)
    feed.load(frames * k)
    can = rig.app._can
    now = rig.now
    rewind = feed.rewind

    def op():
        rewind()
        can(now)

    return op


def _can_idle(rig):
    Feed(rig.hal)
    can = rig.app._can
    now = rig.now

    def op():
        can(now)

    return op


def _loop_idle(rig):
    Feed(rig.hal)
    step = rig.app.step

    def op():
        step()

    return op


def _loop_busy(rig):
    # a pass that does everything that can fall due together: status refresh, essential
    # report, state save, and one of each SpaceCAN frame kind on the bus
    app = rig.app
    hal = rig.hal
    feed = Feed(hal)
    for make in (heartbeat, sync, telecommand, ping):
        feed.load(rig.frames(make))
    rewind = feed.rewind

    def op():
        rewind()
        app._next_status = 0
        app._next_report = 0
        app._next_save = 0
        app._dirty = True
        app.step()
        hal.uart_tx[0] = bytearray()

    return op


def _essential(rig):
    from obsw.frames import cltu, tc
    from obsw.reconfig.essential import HPC_LINES, TARGET_BOTH, Hpc

    app = rig.app
    hal = rig.hal
    Feed(hal)
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

    return op


def _essential_secured(rig, algorithm):
    # the same HPCs as essential_tc, each frame authenticated on the essential MAP's SA (SPI
    # 63): HMAC-SHA-256, or AES-256-GCM (on a board without cryptolib, AES in Python)
    from obsw.frames import cltu, sdls, tc
    from obsw.frames.sdls_gcm import GcmSecurityAssociation
    from obsw.reconfig.essential import HPC_LINES, TARGET_BOTH, Hpc

    key = bytes(range(32))

    def sa():
        if algorithm == "gcm":
            return GcmSecurityAssociation(63, 0, key, 63, reserve_block=1 << 20)
        return sdls.SecurityAssociation(63, 0, key, 63)

    app = rig.app
    hal = rig.hal
    app.essential.frames.security = sdls.TcSecurity([sa()])
    sender = sdls.TcSecurity([sa()])
    values = []
    for i in range(12):  # every measured operation takes a fresh frame (anti-replay)
        hpc = Hpc(HPC_LINES, (0x0F0, (0x0A0, 0x050)[i & 1]), TARGET_BOTH)
        data = sender.apply(SCID, 0, tc.Segment(63, hpc.packet()).pack(), True)
        values.append(cltu.encode(tc.TcFrame(SCID, 0, data, i, bypass=True).pack()))
    state = [0]

    def op():
        k = state[0]
        state[0] = k + 1
        hal.uart_rx[0].extend(values[k])
        app.step()
        hal.uart_tx[0] = bytearray()

    return op


def _sgm_write(rig):
    from obsw.reconfig.app import RECORD_CONTEXT

    sgm = rig.app.sgm
    payload = b"\x00\x01\x02\x03"

    def op():
        sgm.write(RECORD_CONTEXT, payload)

    return op


def _sgm_read(rig):
    from obsw.reconfig.app import RECORD_CONTEXT

    sgm = rig.app.sgm
    sgm.write(RECORD_CONTEXT, b"\x00\x01\x02\x03")

    def op():
        sgm.read(RECORD_CONTEXT)

    return op


def _pus_tc_decode(rig):
    from obsw.pus.tc import PusTc

    raw = PusTc(0x65, 17, 1, b"", 7).pack()
    unpack = PusTc.unpack

    def op():
        unpack(raw)

    return op


def _update_verify(rig):
    """The Ed25519 signature of a one-module update package's manifest (355 bytes, signed
    with cryptography on the ground), verified in Python as the board does."""
    from obsw.update.ed25519 import verify

    ab = "ab" * 32
    body = (
        '{"base":null,"created":"2026-11-25T00:00:00Z","files":[{"path":"obsw/reconfig/app.mpy",'
        '"sha256":"%s","size":21000}],"format":1,"mission":"sample-spacecraft",'
        '"target":"reconfig","tree":{"obsw/reconfig/app.mpy":"%s"},"version":"1.1"}' % (ab, ab)
    ).encode()
    key = bytes.fromhex("03a107bff3ce10be1d70dd18e74bc09967e4d6309ba50d5f1ddc8664125531b8")
    sig = bytes.fromhex(
        "08d5bde0301c6b6212a34d6b7b8c6c549a58e950c4f6407cf5c103c10d45ee3a"
        "7eefc32eadb2ef32b10974d85d0e584c658014beacdd1cdb8c9b2a289cc23b03"
    )

    def op():
        if not verify(key, sig, body):
            raise AssertionError("the package's signature did not verify")

    return op


def _pus_tm_encode(rig):
    from obsw.pus.tm import PusTm

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
    from obsw.pluto.interp import Procedure, load
    from obsw.pluto.system import SimulatedSystem

    # one statement per operation (Procedure.step: the loop's `i := i + 1;` or its test)
    p = Procedure(load(PLUTO), SimulatedSystem({}))
    p.start(0)
    step = p.step

    def op():
        step(0)

    return op


def _nothing(rig):
    def op():
        pass

    return op


BATCH = 16  # frames per poll in the "at full load" cases

NO_RIG = ("pus_tc_decode", "pus_tm_encode", "pluto_statement")

OPS = {
    "empty": _nothing,
    "gc_collect": _nothing,
    "frame_heartbeat": lambda rig: _frame_op(rig, heartbeat),
    "frame_sync": lambda rig: _frame_op(rig, sync),
    "frame_tc_20_1": lambda rig: _frame_op(rig, telecommand),
    "frame_ping_17_1": lambda rig: _frame_op(rig, ping),
    "frame_other": lambda rig: _frame_op(rig, other_node),
    "batch_heartbeat": lambda rig: _frames_op(rig, heartbeat, BATCH),
    "batch_sync": lambda rig: _frames_op(rig, sync, BATCH),
    "batch_tc_20_1": lambda rig: _frames_op(rig, telecommand, BATCH),
    "batch_ping_17_1": lambda rig: _frames_op(rig, ping, BATCH),
    "batch_other": lambda rig: _frames_op(rig, other_node, BATCH),
    "can_idle": _can_idle,
    "loop_idle": _loop_idle,
    "loop_busy": _loop_busy,
    "essential_tc": _essential,
    "essential_tc_hmac": lambda rig: _essential_secured(rig, "hmac"),
    "essential_tc_gcm": lambda rig: _essential_secured(rig, "gcm"),
    "sgm_write": _sgm_write,
    "sgm_read": _sgm_read,
    "pus_tc_decode": _pus_tc_decode,
    "pus_tm_encode": _pus_tm_encode,
    "update_verify": _update_verify,
    "pluto_statement": _pluto,
}

ALLOC_OPS = 4  # operations measured for their allocations, each with the collector off
# operations that allocate more than the heap holds (Python big integers): measured with the
# collector on, so their counts include their collections, and their allocation is not measured
COLLECTING = ("update_verify",)


def _timer_start():
    _mem[_TIMER] = 0
    _mem[_TIMER + 8] = _TOP
    _mem[_VALUE] = _TOP
    _mem[_TIMER] = 1  # enable, no interrupt


def run(name, n):
    # SysTick masked from the start: its interrupts land where the host's timing put the
    # virtual clock (the REPL polls the UART), and the words they stack, left in the holes of
    # later C frames, are read by the collector's conservative stack scan
    csr = _mem[_SYST_CSR]
    _mem[_SYST_CSR] = csr & ~_TICKINT
    try:
        _run(name, n)
    finally:
        _mem[_SYST_CSR] = csr


def _run(name, n):
    rig = None if name in NO_RIG else Rig()
    op = OPS[name](rig)
    op()  # first use: anything created lazily exists before counting starts
    gc.collect()
    free = gc.mem_free()
    allocated = 0
    for _ in range(0 if name in COLLECTING else ALLOC_OPS):
        gc.collect()
        gc.disable()
        before = gc.mem_alloc()
        op()
        allocated += gc.mem_alloc() - before
        gc.enable()
    ticks = [0] * n
    collect = gc.collect
    mem = _mem
    _timer_start()
    if True:  # SysTick is masked (run): nothing but the operation between the two readings
        if name == "gc_collect":
            for i in range(n):
                collect()
                a = mem[_VALUE]
                collect()
                b = mem[_VALUE]
                ticks[i] = (a - b) & _TOP
        else:
            for i in range(n):
                collect()
                a = mem[_VALUE]
                op()
                b = mem[_VALUE]
                ticks[i] = (a - b) & _TOP
        collect()
        a = mem[_VALUE]
        collect()
        b = mem[_VALUE]
        gc_ticks = (a - b) & _TOP
    print("ticks", name, " ".join(str(t) for t in ticks))
    print("alloc", name, allocated // ALLOC_OPS)
    print("heap", name, free)
    print("gc", name, gc_ticks)
    if rig is None:
        print("ok", name)
        return
    app = rig.app
    print(
        "ok",
        name,
        "steps",
        app.counters["steps"],
        "errors",
        app.counters["loop_errors"],
        "hpcs",
        app.essential.counters["hpcs"],
        "bits",
        app.bits,
    )
