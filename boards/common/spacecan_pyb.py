"""SpaceCAN on a Pyboard: drives a core controller or responder over pyb.CAN(1) and pyb.CAN(2).

A thin shim with the same shape as the host's python-can adapter: frames in from both buses,
node.poll(now), frames out, transmit failures and bus-off reported to the node as tx_error.
Nothing touches hardware at import; `PybCanDriver.open(node)` creates the CAN objects.
"""

from obsw.compat import monotonic
from obsw.spacecan.controller import Controller
from obsw.spacecan.ids import FUNCTION_MASK, ID_HEARTBEAT, ID_REP, ID_SCET, ID_SYNC, ID_UTC


class PybCanDriver:
    """Moves frames between two pyb.CAN objects (A, B) and one SpaceCAN node."""

    def __init__(self, node, can_a, can_b, clock=monotonic):
        self.node = node
        self.cans = (can_a, can_b)
        self.clock = clock
        self.counters = {"rx": 0, "tx": 0, "tx_errors": 0, "bus_off": 0}
        self._buf = [bytearray(8), bytearray(8)]

    @classmethod
    def open(cls, node, baudrate=1000000, buses=(1, 2)):
        """Open CAN(1) and CAN(2) in normal mode with SpaceCAN receive filters."""
        import pyb

        cans = []
        for b in buses:
            can = pyb.CAN(b)
            can.init(pyb.CAN.NORMAL, baudrate=baudrate, auto_restart=True)
            if isinstance(node, Controller):
                can.setfilter(0, pyb.CAN.MASK16, 0, (ID_REP, FUNCTION_MASK, ID_REP, FUNCTION_MASK))
            else:
                req = node._req_id
                can.setfilter(0, pyb.CAN.LIST16, 0, (ID_HEARTBEAT, ID_SYNC, ID_SCET, ID_UTC))
                can.setfilter(1, pyb.CAN.LIST16, 0, (req, req, req, req))
            cans.append(can)
        return cls(node, cans[0], cans[1])

    def step(self):
        """Read everything waiting on both buses, run deadlines, send what the node produced."""
        node = self.node
        for bus in (0, 1):
            can = self.cans[bus]
            while can.any(0):
                msg = can.recv(0, timeout=0)
                # (id, isext, rtr, fmi, data) on current firmware, (id, rtr, fmi, data) on older
                if len(msg) == 5 and (msg[1] or msg[2]):
                    continue
                self.counters["rx"] += 1
                node.receive(bus, msg[0], msg[-1], self.clock())
        node.poll(self.clock())
        self.flush()

    def flush(self):
        node = self.node
        frames = node.take_frames()
        while frames:
            for bus, can_id, data in frames:
                try:
                    self.cans[bus].send(data, can_id, timeout=0)
                    self.counters["tx"] += 1
                except OSError:  # all mailboxes busy or the controller is bus-off
                    self.counters["tx_errors"] += 1
                    node.tx_error(bus, self.clock())
            frames = node.take_frames()

    def check_state(self):
        """Report bus-off on either bus to the node (auto_restart brings the bus back)."""
        import pyb

        for bus in (0, 1):
            if self.cans[bus].state() == pyb.CAN.BUS_OFF:
                self.counters["bus_off"] += 1
                self.node.tx_error(bus, self.clock())

    def next_wait_ms(self, limit_ms=10):
        """Milliseconds until the node's next deadline, at most limit_ms."""
        due = self.node.next_deadline()
        if due is None:
            return limit_ms
        ms = int((due - self.clock()) * 1000)
        return 0 if ms < 0 else (limit_ms if ms > limit_ms else ms)

    async def run(self, period_ms=1):
        """Serve both buses forever as an asyncio task; the application reads node.take_events().

        pyb.CAN is polled every period_ms (frames wait in the hardware FIFOs meanwhile).
        """
        import asyncio

        n = 0
        while True:
            self.step()
            n += 1
            if n % 100 == 0:
                self.check_state()
            await asyncio.sleep_ms(period_ms)
