"""Helpers for the CFDP core tests: two entities over a simulated lossy link with a simulated
clock (deterministic; the same on CPython and MicroPython)."""

from obsw.cfdp.entity import CfdpEntity
from obsw.cfdp.filestore import MemoryFilestore
from obsw.cfdp.mib import Mib, RemoteEntity


class Rng:
    """xorshift32: a small deterministic generator that behaves the same everywhere."""

    def __init__(self, seed):
        self.s = (seed * 2654435761 + 1) & 0xFFFFFFFF or 1

    def next(self):
        x = self.s
        x ^= (x << 13) & 0xFFFFFFFF
        x ^= x >> 17
        x ^= (x << 5) & 0xFFFFFFFF
        self.s = x
        return x

    def chance(self, p):
        return p > 0 and self.next() % 1000000 < p * 1000000


def make_pair(a_id=1, b_id=2, files_a=None, files_b=None, persist=False, **remote_kw):
    kw = {"ack_interval": 2.0, "nak_interval": 2.0, "inactivity": 30.0, "max_segment": 64}
    kw.update(remote_kw)
    fa = MemoryFilestore(files_a or {})
    fb = MemoryFilestore(files_b or {})
    a = CfdpEntity(Mib(a_id, [RemoteEntity(b_id, **kw)]), fa, persist=persist)
    b = CfdpEntity(Mib(b_id, [RemoteEntity(a_id, **kw)]), fb, persist=persist)
    return a, b


class Link:
    """Carries PDUs between two entities; drops, duplicates, corrupts and reorders them."""

    def __init__(self, a, b, seed=1, loss=0.0, dup=0.0, corrupt=0.0, reorder=0.0, drop=None):
        self.ents = [a, b]
        self.rng = Rng(seed)
        self.loss = loss
        self.dup = dup
        self.corrupt = corrupt
        self.reorder = reorder
        self.drop = drop  # optional callable(side, pdu_bytes) -> True to drop
        self.now = 0.0
        self.sent = [0, 0]
        self.dropped = [0, 0]
        self.indications = [[], []]
        self.hook = None  # optional callable(link) run every round

    def _mangle(self, side, pdu, out):
        rng = self.rng
        if (self.drop is not None and self.drop(side, pdu)) or rng.chance(self.loss):
            self.dropped[side] += 1
            return
        if rng.chance(self.corrupt):
            b = bytearray(pdu)
            i = rng.next() % len(b)
            b[i] ^= 1 << (rng.next() % 8)
            pdu = bytes(b)
        out.append(pdu)
        if rng.chance(self.dup):
            out.append(pdu)

    def step(self):
        """One round: each side transmits, the other receives. True if anything moved."""
        moved = False
        for side in (0, 1):
            src = self.ents[side]
            dst = self.ents[1 - side]
            out = []
            for _dest, pdu in src.transmit(self.now, 32):
                self.sent[side] += 1
                self._mangle(side, pdu, out)
            if self.reorder:
                for i in range(len(out) - 1):
                    if self.rng.chance(self.reorder):
                        out[i], out[i + 1] = out[i + 1], out[i]
            for pdu in out:
                dst.receive(pdu, self.now)
                moved = True
        for side in (0, 1):
            self.indications[side].extend(self.ents[side].pop_indications())
        return moved

    def run(self, max_time=10000.0, max_rounds=200000, until=None):
        """Run until both entities are idle (or ``until()``); jumps the clock to deadlines."""
        rounds = 0
        while rounds < max_rounds:
            rounds += 1
            if self.hook is not None:
                self.hook(self)
            moved = self.step()
            for side in (0, 1):
                self.ents[side].poll(self.now)
                self.indications[side].extend(self.ents[side].pop_indications())
            if until is not None and until():
                return True
            if moved or any(e.pending() for e in self.ents):
                continue
            ds = [d for d in (e.next_deadline() for e in self.ents) if d is not None]
            if not ds:
                return True
            t = min(ds)
            if t > max_time:
                return False
            self.now = max(self.now, t)
        return False

    def kinds(self, side, kind):
        return [i for i in self.indications[side] if i.kind == kind]

    def finished(self, side):
        return self.kinds(side, "finished")


def payload(n, seed=7):
    """``n`` pseudo-random bytes, filled in place (a list of ``n`` ints would take 4n bytes of a
    board's heap)."""
    r = Rng(seed)
    b = bytearray(n)
    for i in range(n):
        b[i] = r.next() & 0xFF
    return bytes(b)


def directive(pdu):
    """The directive code of a raw PDU, or None for file data."""
    if pdu[0] & 0x10:
        return None
    return pdu[4 + 2 * (((pdu[3] >> 4) & 7) + 1) + (pdu[3] & 7) + 1]


def ack_of(pdu):
    """For a raw ACK PDU, the directive code it acknowledges."""
    return pdu[4 + 2 * (((pdu[3] >> 4) & 7) + 1) + (pdu[3] & 7) + 2] >> 4
