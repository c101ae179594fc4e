"""Frame synchronization of CCSDS 131.0-B on the ground: ASM search tolerating bit errors,
inverted polarity, re-acquisition after bit slips, and search/verify/lock/flywheel states."""

from obsw.compat import bytes_ops, const
from obsw.frames.asm import ASM

SEARCH = const(0)
VERIFY = const(1)
LOCK = const(2)
FLYWHEEL = const(3)
STATE_NAMES = ("search", "verify", "lock", "flywheel")
_ASM_BITS = const(32)

_popcount = []
_ZERO_ONE = b"01" + bytes(254)
_ONE_OF = bytes(48) + b"\x00\x01" + bytes(206)  # "0" -> 0, "1" -> 1


def _pc():
    if not _popcount:
        _popcount.extend(bin(i).count("1") for i in range(256))
    return _popcount


def unpack_bits(data):
    """Octets to bits, one per octet (0 or 1), most significant bit first."""
    if not data:
        return b""
    if bytes_ops():
        text = bin(int.from_bytes(bytes(data), "big") | (1 << (8 * len(data))))[3:]
        return text.encode().translate(_ONE_OF)
    out = bytearray(8 * len(data))
    i = 0
    for b in data:
        for k in range(7, -1, -1):
            out[i] = (b >> k) & 1
            i += 1
    return bytes(out)


def pack_bits(bits, invert=False):
    """Bits (one per octet) to octets, most significant bit first; ``invert`` flips them."""
    n = len(bits) // 8
    if n == 0:
        return b""
    if bytes_ops():
        v = int(bytes(bits[: 8 * n]).translate(_ZERO_ONE), 2)
        if invert:
            v ^= (1 << (8 * n)) - 1
        return v.to_bytes(n, "big")
    out = bytearray(n)
    flip = 0xFF if invert else 0
    for i in range(n):
        v = 0
        for k in range(8 * i, 8 * i + 8):
            v = (v << 1) | bits[k]
        out[i] = v ^ flip
    return bytes(out)


class SyncedFrame:
    """What the synchronizer found: the ``data`` behind an ASM (polarity corrected), the bit
    errors in that ASM, whether it was seen in lock, and the state it was taken in."""

    def __init__(self, data, asm_errors, state, inverted, position):
        self.data = data
        self.asm_errors = asm_errors
        self.state = state
        self.inverted = inverted
        self.position = position  # bit offset of the ASM in the whole stream

    def __repr__(self):
        return "SyncedFrame(%d octets, %s, ASM errors %d%s)" % (
            len(self.data),
            STATE_NAMES[self.state],
            self.asm_errors,
            ", inverted" if self.inverted else "",
        )


class FrameSync:
    """Find ``length``-octet frames (what follows each ASM) in a stream of bits.

    SEARCH slides over the stream for the ASM or its inverse with at most ``search_errors``
    wrong bits (an inverse means BPSK locked 180 degrees off: the frames are inverted);
    VERIFY wants ``verify`` ASMs one frame apart before LOCK; in LOCK an ASM with more than
    ``lock_errors`` wrong bits is looked for up to ``slip`` bits early or late (a bit slip),
    else the frame is still given (FLYWHEEL) until ``flywheel`` ASMs in a row are missed, which
    is a loss of lock and a new search. ``events`` lists ("lock" | "loss" | "slip", bit
    position); the counters say how often each happened.
    """

    def __init__(self, length, search_errors=3, lock_errors=6, verify=2, flywheel=3, slip=2,
                 asm=ASM):  # fmt: skip
        self.length = length
        self.search_errors = search_errors
        self.lock_errors = lock_errors
        self.verify = verify
        self.flywheel = flywheel
        self.slip = slip
        self._asm = int.from_bytes(asm, "big")
        self.state = SEARCH
        self.inverted = False
        self.events = []
        self.locks = 0
        self.losses = 0
        self.slips = 0
        self.frames = 0
        self.asm_errors = 0
        self.skipped = 0  # bits that were not part of any frame
        self._buf = b""
        self._base = 0  # stream position of _buf[0]
        self._count = 0
        self._kept = 0  # bits of _buf already consumed (held for a slip look-back)

    def _errors(self, buf, pos):
        # wrong bits of the ASM at pos, for the current polarity
        v = 0
        for i in range(pos, pos + _ASM_BITS):
            v = (v << 1) | buf[i]
        x = v ^ self._asm
        if self.inverted:
            x ^= 0xFFFFFFFF
        pc = _pc()
        return pc[x & 255] + pc[(x >> 8) & 255] + pc[(x >> 16) & 255] + pc[x >> 24]

    def _search(self, buf, pos):
        # first position at or after pos with the ASM (either polarity) within tolerance
        pc = _pc()
        asm = self._asm
        limit = self.search_errors
        n = len(buf)
        if n - pos < _ASM_BITS:
            return -1, pos
        v = 0
        for i in range(pos, pos + _ASM_BITS - 1):
            v = (v << 1) | buf[i]
        for i in range(pos + _ASM_BITS - 1, n):
            v = ((v << 1) | buf[i]) & 0xFFFFFFFF
            x = v ^ asm
            e = pc[x & 255] + pc[(x >> 8) & 255] + pc[(x >> 16) & 255] + pc[x >> 24]
            if e <= limit:
                self.inverted = False
                return i - _ASM_BITS + 1, e
            if e >= _ASM_BITS - limit:
                self.inverted = True
                return i - _ASM_BITS + 1, _ASM_BITS - e
        return -1, n - _ASM_BITS + 1

    def flush(self):
        """The frame still held back to look for a late ASM (end of a recording)."""
        return self.feed(b"", True)

    def feed(self, bits, final=False):
        """Take bits (one per octet); return the SyncedFrames completed by them."""
        buf = self._buf + bytes(bits) if self._buf else bytes(bits)
        out = []
        pos = self._kept  # the bits before it are kept to find an ASM that came early
        total = _ASM_BITS + 8 * self.length
        while True:
            if self.state == SEARCH:
                found, e = self._search(buf, pos)
                if found < 0:
                    self.skipped += e - pos
                    pos = e
                    break
                self.skipped += found - pos
                pos = found
                self.state = VERIFY
                self._count = 0
            margin = 0 if final or self.state == VERIFY else self.slip
            if len(buf) - pos < total + margin:
                break
            e = self._errors(buf, pos)
            if self.state != VERIFY and e > self.lock_errors:
                best = None
                for d in range(1, self.slip + 1):
                    for off in (-d, d):
                        if pos + off >= 0:
                            eo = self._errors(buf, pos + off)
                            if eo <= self.lock_errors and (best is None or eo < best[1]):
                                best = (off, eo)
                    if best is not None:
                        break
                if best is not None:
                    if best[0] > 0:
                        self.skipped += best[0]
                    pos += best[0]
                    e = best[1]
                    self.slips += 1
                    self.events.append(("slip", self._base + pos))
            if self.state == VERIFY:
                if e > self.search_errors:
                    self.state = SEARCH
                    pos += 1
                    self.skipped += 1
                    continue
                self._count += 1
                if self._count >= self.verify:
                    self.state = LOCK
                    self.locks += 1
                    self.events.append(("lock", self._base + pos))
            elif e <= self.lock_errors:
                self.state = LOCK
                self._count = 0
            else:
                self._count += 1
                self.state = FLYWHEEL
                if self._count >= self.flywheel:
                    self.state = SEARCH
                    self.losses += 1
                    self.events.append(("loss", self._base + pos))
                    pos += 1
                    self.skipped += 1
                    continue
            data = pack_bits(buf[pos + _ASM_BITS : pos + total], self.inverted)
            out.append(SyncedFrame(data, e, self.state, self.inverted, self._base + pos))
            self.frames += 1
            self.asm_errors += e
            pos += total
        keep = min(pos, self.slip) if self.state != SEARCH else 0
        self._buf = buf[pos - keep :]
        self._base += pos - keep
        self._kept = keep
        return out

    def take_events(self):
        """The events since the last call."""
        ev = self.events
        self.events = []
        return ev
