"""Soft-decision Viterbi decoder for the CCSDS rate 1/2, K=7 convolutional code (131.0-B 3.3)."""

from obsw.compat import const, speedups
from obsw.frames.conv import branch_symbols

DEFAULT_TRACEBACK = const(96)  # bits kept before deciding: 5 * (K - 1) and more, as is usual
_STATES = const(64)

_branch = []


def _branch_table():
    # For old state j < 32 and input 0, which of the four metrics (s1+s2, s1-s2, -s1+s2,
    # -s1-s2) measures the branch: old state j + 32 and input 1 give the opposite symbols.
    if not _branch:
        for j in range(32):
            c1, c2 = branch_symbols(j, 0)
            _branch.append((1 - c1) * 2 + (1 - c2))
    return _branch


def soft_from_bits(data, amplitude=127):
    """Hard octets as soft symbols (one per bit, MSB first): +amplitude for 1, -amplitude for 0."""
    out = []
    for b in data:
        for i in range(7, -1, -1):
            out.append(amplitude if (b >> i) & 1 else -amplitude)
    return out


class Viterbi27:
    """Decode soft symbols (one per coded bit, C1 then C2, positive means 1, magnitude the
    confidence: signed 8-bit values or floats; hard decisions are +-1) into bits.

    ``feed`` returns the bits (one per octet, 0 or 1) decided so far, ``traceback`` bits behind
    the newest symbol; ``flush`` returns the rest from the best state. An odd symbol left over
    waits for its pair. On CPython, signed 8-bit input (``array('b')``, ``bytes`` read as
    signed) goes to the C decoder in ``obsw_speedups`` when it is built; both give the same bits.
    """

    def __init__(self, traceback=DEFAULT_TRACEBACK, fast=None):
        self.traceback = traceback
        sp = speedups() if fast is None or fast else None
        self._c = getattr(sp, "viterbi27", None) if sp is not None else None
        self._c_chainback = getattr(sp, "viterbi27_chainback", None) if self._c else None
        self.bits_out = 0
        self.reset(0)

    def reset(self, state=None):
        """Start again; ``state`` None: any encoder state equally likely (joining a stream)."""
        if state is None:
            self._metrics = [0] * _STATES
        else:
            self._metrics = [-(1 << 20)] * _STATES
            self._metrics[state] = 0
        # C path: 8 octets of decisions per bit; Python: one int per bit
        self._decisions = bytearray() if self._c else []
        self._pending = []
        self._skip = False

    def realign(self):
        """Start again one symbol later: the C1/C2 pairing of a stream joined in the middle
        was wrong (the symbol held back, if any, is dropped, else the next one will be)."""
        pending = self._pending[1:] if self._pending else None
        self.reset(None)
        self._skip = pending is None
        self._pending = pending or []

    @property
    def skipping(self):
        """True while the next symbol fed is to be dropped (after ``realign``)."""
        return self._skip

    def metric_spread(self):
        """Best path metric minus the mean: grows with clean symbols, a symbol-pair slip or
        noise keeps it low (used to choose the symbol alignment of a stream)."""
        m = self._metrics
        return max(m) - sum(m) / _STATES

    def _steps(self):
        n = len(self._decisions)
        return n // 8 if self._c else n

    def feed(self, soft):
        """Take soft symbols; return the bits now decided (one per octet, 0 or 1)."""
        if self._skip and len(soft):
            self._skip = False
            soft = soft[1:]
        if self._pending:
            soft = self._pending + list(soft)
        n = len(soft) & ~1
        self._pending = list(soft[n:])
        if n:
            if self._c is not None:
                if not isinstance(soft, (bytes, bytearray)) and (
                    getattr(soft, "typecode", None) != "b"
                ):
                    soft = _int8(soft, n)
                self._metrics = self._c(self._metrics, soft, n, self._decisions)
            else:
                self._acs(soft, n)
        steps = self._steps()
        if steps <= self.traceback + 64:
            return b""
        return self._chainback(steps - self.traceback)

    def flush(self):
        """The bits still held, traced back from the best state."""
        return self._chainback(self._steps())

    def _acs(self, syms, n):
        tab = _branch_table()
        p = self._metrics
        decisions = self._decisions
        for i in range(0, n, 2):
            a = syms[i]
            b = syms[i + 1]
            m = (a + b, a - b, b - a, -a - b)
            q = [0] * _STATES
            d = 0
            for j in range(32):
                mu = m[tab[j]]
                p0 = p[j]
                p1 = p[j + 32]
                x = p0 + mu
                y = p1 - mu
                if x >= y:
                    q[2 * j] = x
                else:
                    q[2 * j] = y
                    d |= 1 << (2 * j)
                x = p0 - mu
                y = p1 + mu
                if x >= y:
                    q[2 * j + 1] = x
                else:
                    q[2 * j + 1] = y
                    d |= 2 << (2 * j)
            top = q[0]
            if top > 1 << 24 or top < -(1 << 24):
                q = [v - top for v in q]
            p = q
            decisions.append(d)
        self._metrics = p

    def _chainback(self, count):
        # Trace from the best state through every decision, return the oldest ``count`` bits.
        p = self._metrics
        s = 0
        best = p[0]
        for j in range(1, _STATES):
            if p[j] > best:
                best = p[j]
                s = j
        dec = self._decisions
        self.bits_out += count
        if self._c is not None:
            out = self._c_chainback(dec, s, count)
            del dec[: 8 * count]
            return out
        out = bytearray(count)
        for t in range(len(dec) - 1, -1, -1):
            if t < count:
                out[t] = s & 1
            s = (s >> 1) | (((dec[t] >> s) & 1) << 5)
        del dec[:count]
        return bytes(out)


def _int8(soft, n):
    # the C path reads signed octets: other numbers are rounded and clipped to -127..127
    from array import array

    out = array("b", bytes(n))
    for i in range(n):
        v = int(round(soft[i]))
        out[i] = 127 if v > 127 else (-127 if v < -127 else v)
    return out
