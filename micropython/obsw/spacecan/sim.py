"""An in-memory pair of SpaceCAN buses with a simulated clock and fault injection, for tests.

Nodes are controller or responder state machines (anything with receive / poll /
next_deadline / take_frames). Frames arrive instantly and in order; faults are injected per
bus: kill (everything vanishes, optionally with transmit errors to the sender), drop or corrupt
the next n matching frames, a seeded random drop rate, and injection of arbitrary frames.
"""


class _Rule:
    def __init__(self, action, bus, can_id, count, byte, mask):
        self.action = action
        self.bus = bus
        self.can_id = can_id
        self.count = count
        self.byte = byte
        self.mask = mask

    def matches(self, bus, can_id):
        return (self.bus is None or self.bus == bus) and (
            self.can_id is None or self.can_id == can_id
        )


class SimNetwork:
    """Two simulated buses (0 = A, 1 = B) joining the attached nodes, on a simulated clock."""

    def __init__(self, now=0.0, seed=12345, trace=False):
        self.now = now
        self.nodes = []
        self.alive = [True, True]
        self.tx_errors_when_dead = [False, False]
        self.drop_rate = [0.0, 0.0]
        self.trace = [] if trace else None
        self.counters = {"sent": 0, "delivered": 0, "dropped": 0, "corrupted": 0, "injected": 0}
        self._rules = []
        self._seed = seed & 0x7FFFFFFF or 1

    def attach(self, *nodes):
        for n in nodes:
            self.nodes.append(n)
        return self

    # -- faults --------------------------------------------------------------------------------

    def kill(self, bus, tx_errors=False):
        """Bus stops carrying frames; with tx_errors each sender is told its frames failed."""
        self.alive[bus] = False
        self.tx_errors_when_dead[bus] = tx_errors

    def revive(self, bus):
        self.alive[bus] = True

    def drop(self, count=1, bus=None, can_id=None):
        """Lose the next count frames matching bus / can_id (None = any)."""
        self._rules.append(_Rule("drop", bus, can_id, count, 0, 0))

    def corrupt(self, count=1, bus=None, can_id=None, byte=0, mask=0xFF):
        """XOR byte `byte` of the next count matching frames with mask (frames too short pass)."""
        self._rules.append(_Rule("corrupt", bus, can_id, count, byte, mask))

    def set_drop_rate(self, rate, bus=None):
        """Lose each frame with probability rate (seeded, reproducible)."""
        for b in (0, 1) if bus is None else (bus,):
            self.drop_rate[b] = rate

    def _random(self):
        self._seed = (self._seed * 1103515245 + 12345) & 0x7FFFFFFF
        return self._seed / 2147483648

    def inject(self, bus, can_id, data, sender=None):
        """Put a frame on bus as if some other station sent it."""
        self.counters["injected"] += 1
        self._carry(sender, bus, can_id, bytes(data))

    # -- carrying frames -----------------------------------------------------------------------

    def _carry(self, sender, bus, can_id, data):
        self.counters["sent"] += 1
        if not self.alive[bus]:
            self.counters["dropped"] += 1
            if (
                self.tx_errors_when_dead[bus]
                and sender is not None
                and hasattr(sender, "tx_error")
            ):
                sender.tx_error(bus, self.now)
            return
        for rule in self._rules:
            if rule.count > 0 and rule.matches(bus, can_id):
                rule.count -= 1
                if rule.action == "drop":
                    self.counters["dropped"] += 1
                    return
                if rule.byte < len(data):
                    b = bytearray(data)
                    b[rule.byte] ^= rule.mask
                    data = bytes(b)
                    self.counters["corrupted"] += 1
                break
        self._rules = [r for r in self._rules if r.count > 0]
        if self.drop_rate[bus] and self._random() < self.drop_rate[bus]:
            self.counters["dropped"] += 1
            return
        if self.trace is not None:
            self.trace.append((self.now, bus, can_id, data))
        for node in self.nodes:
            if node is not sender:
                node.receive(bus, can_id, data, self.now)
                self.counters["delivered"] += 1

    def pump(self):
        """Carry frames until no node has any left to send."""
        moved = True
        while moved:
            moved = False
            for node in self.nodes:
                frames = node.take_frames()
                if frames:
                    moved = True
                    for bus, can_id, data in frames:
                        self._carry(node, bus, can_id, data)

    def next_deadline(self):
        best = None
        for node in self.nodes:
            t = node.next_deadline()
            if t is not None and (best is None or t < best):
                best = t
        return best

    def run(self, duration):
        """Advance the clock by duration, polling each node at its deadlines."""
        self.run_until(None, duration)

    def run_until(self, predicate, timeout):
        """Advance until predicate() is true or timeout seconds pass; return its last value."""
        end = self.now + timeout
        stuck = 0
        while True:
            for node in self.nodes:
                node.poll(self.now)
            self.pump()
            if predicate is not None and predicate():
                return True
            t = self.next_deadline()
            if t is None or t > end:
                self.now = end
                for node in self.nodes:
                    node.poll(self.now)
                self.pump()
                return bool(predicate()) if predicate is not None else False
            if t <= self.now:
                stuck += 1
                if stuck > 10000:
                    raise RuntimeError("simulated nodes keep a deadline at %r" % t)
            else:
                stuck = 0
                self.now = t


class NetworkClock:
    """An interaction-layer clock on the network's simulated time, for IL nodes in tests.

    ``now()`` is the network's time. ``sleep(seconds)`` is what a blocked IL caller does: it
    lets the watched IL nodes run their providers and callbacks first, and if they had nothing
    to do, moves the network on to its next deadline (or by ``seconds`` if that comes first).
    It returns early in either case, so the caller re-checks what it waits for.
    """

    def __init__(self, network):
        self.network = network
        self.nodes = []

    def watch(self, node):
        """Run ``node.poll()`` whenever a caller waits (a node built on this clock)."""
        self.nodes.append(node)
        return node

    def now(self):
        return self.network.now

    def sleep(self, seconds):
        busy = 0
        for node in self.nodes:
            busy += node.poll()
        if busy:
            return
        net = self.network
        end = net.now + (seconds if seconds > 0 else 0)
        t = net.next_deadline()
        step = (end if t is None or t > end else t) - net.now
        net.run(step if step > 0 else 0)
