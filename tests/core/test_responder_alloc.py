"""Heap allocated per SpaceCAN frame the reconfiguration module handles (not a timing test).

Garbage on a board is paid for by collections that stall the main loop, so the bytes each frame
allocates are a budget (docs/reconfiguration.md; MicroPython unix port, 64-bit; gc.mem_alloc()
around a few frames with the collector off). A change that allocates more per frame fails here;
one that allocates less should lower the figures here. CPython has no gc.mem_alloc, so there
the test is skipped and says why.
"""

import gc
import unittest

from obsw.reconfig.app import ReconfigApp
from obsw.reconfig.models import ModelHal
from obsw.reconfig.node import NODE_NOMINAL, definition
from obsw.spacecan.controller import Controller

# bytes per frame on the 64-bit unix port (the Cortex-M figures: docs/benchmarks/board.md)
LIMITS = {
    "idle poll": 0,
    "heartbeat": 64,
    "sync": 32,
    "another node's request": 32,
    "ping 17,1": 96,
    "TC 20,1": 288,
}
FRAMES = 8
HAS_MEM_ALLOC = hasattr(gc, "mem_alloc")


class Rig:
    def __init__(self):
        # EEPROMs of 2 KiB: room for the records, and the test fits a Pyboard's heap
        self.hal = ModelHal(rtc_seconds=20089 * 86400, eeprom_size=2048)
        self.app = ReconfigApp(self.hal)
        self.ctrl = Controller(heartbeat_period=0.5)
        self.ctrl.add_node(NODE_NOMINAL, definition(NODE_NOMINAL))
        self.ctrl.start(0.0)
        self.hal.idle(self.app.step())
        self.ctrl.take_frames()
        self.hal.can_tx = []
        self.now = self.hal.now / 1000000

    def frames(self, kind):
        c = self.ctrl
        if kind == "heartbeat":
            c._send_heartbeat(self.now)
        elif kind == "sync":
            c.send_sync(self.now)
        elif kind == "ping 17,1":
            c.request(NODE_NOMINAL, 17, 1, b"", self.now)
        elif kind == "TC 20,1":
            c.request_parameters(NODE_NOMINAL, [1], self.now)
        elif kind == "another node's request":
            return [(0, 0x280 + NODE_NOMINAL + 1, b"\x00\x00\x11\x01")]  # a ping to node 11
        return [(bus, can_id, bytes(data)) for bus, can_id, data in c.take_frames()]

    def allocated_per_frame(self, kind):
        """Bytes allocated per pass of the application's SpaceCAN poll that handles one frame
        of ``kind`` (and sends its replies), the hardware layer allocating nothing."""
        frames = self.frames(kind) if kind != "idle poll" else []
        feed = Feed()
        self.hal.can_recv = feed.recv
        self.hal.can_send = feed.send
        can = self.app._can
        now = self.now
        for f in frames:  # once first: whatever is made lazily exists before counting
            feed.put(f)
            can(now)
        if not frames:
            can(now)
        sent = feed.sent
        gc.collect()
        gc.disable()
        try:
            before = gc.mem_alloc()
            for _ in range(FRAMES):
                for f in frames:
                    feed.put(f)
                    can(now)
                if not frames:
                    can(now)
            after = gc.mem_alloc()
        finally:
            gc.enable()
        return (after - before) // FRAMES, feed.sent - sent


class Feed:
    """A hardware layer's CAN side that hands over one frame and allocates nothing."""

    def __init__(self):
        self.frame = None
        self.bus = 0
        self.sent = 0

    def put(self, f):
        self.bus = f[0]
        self.frame = (f[1], f[2])

    def recv(self, bus):
        f = self.frame
        if f is None or self.bus != bus:
            return None
        self.frame = None
        return f

    def send(self, bus, can_id, data):
        self.sent += 1
        return True


class TestAllocationsPerFrame(unittest.TestCase):
    @unittest.skipIf(not HAS_MEM_ALLOC, "gc.mem_alloc() is MicroPython's; CPython has none")
    def test_within_the_stated_budget(self):
        for kind in LIMITS:
            got, sent = Rig().allocated_per_frame(kind)
            if kind in ("ping 17,1", "TC 20,1"):
                self.assertTrue(sent >= FRAMES, "%s: %d replies to %d" % (kind, sent, FRAMES))
            self.assertTrue(
                got <= LIMITS[kind],
                "%s: %d bytes allocated per frame, the budget is %d" % (kind, got, LIMITS[kind]),
            )


if __name__ == "__main__":
    unittest.main()
