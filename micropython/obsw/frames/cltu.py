"""Command Link Transmission Units (CCSDS 231.0-B): start sequence, BCH codeblocks, tail."""

from obsw.compat import const
from obsw.frames.bch import correct, parity
from obsw.frames.errors import CltuError
from obsw.frames.randomizer import randomize_tc

START_SEQUENCE = b"\xeb\x90"
TAIL_SEQUENCE = b"\xc5\xc5\xc5\xc5\xc5\xc5\xc5\x79"
FILL = const(0x55)
_MAX_BLOCKS = const(147)  # a 1024-byte TC frame needs 147 codeblocks


def encode(frame, randomize=False):
    """Return the CLTU carrying ``frame`` (optionally TC-randomized before coding)."""
    data = randomize_tc(frame) if randomize else frame
    n = len(data)
    out = bytearray(START_SEQUENCE)
    block = bytearray(7)
    for i in range(0, n, 7):
        chunk = data[i : i + 7]
        if len(chunk) == 7:
            out.extend(chunk)
            out.append(parity(chunk))
        else:
            block[: len(chunk)] = chunk
            for j in range(len(chunk), 7):
                block[j] = FILL
            out.extend(block)
            out.append(parity(block))
    out.extend(TAIL_SEQUENCE)
    return bytes(out)


def decode(cltu, derandomize=False):
    """Decode one whole CLTU; return (data, corrected_bits).

    ``data`` is every information byte of every codeblock, fill included (the frame's own length
    field tells where the frame ends). Raises CltuError on a missing start or tail sequence or an
    uncorrectable codeblock.
    """
    if len(cltu) < 18:
        raise CltuError("CLTU too short: %d bytes, needs 18" % len(cltu))
    if cltu[:2] != START_SEQUENCE:
        raise CltuError("CLTU start sequence is %r, expected EB90" % (bytes(cltu[:2]),))
    if (len(cltu) - 2) % 8:
        raise CltuError("CLTU body of %d bytes is not whole codeblocks" % (len(cltu) - 2))
    if cltu[-8:] != TAIL_SEQUENCE:
        raise CltuError("CLTU has no tail sequence")
    buf = bytearray(cltu[2:-8])
    out = bytearray()
    fixed = 0
    for off in range(0, len(buf), 8):
        r = correct(buf, off)
        if r < 0:
            raise CltuError("CLTU codeblock %d is uncorrectable" % (off // 8), off // 8)
        fixed += r
        out.extend(buf[off : off + 7])
    if not out:
        raise CltuError("CLTU carries no codeblock")
    data = bytes(out)
    return (randomize_tc(data) if derandomize else data), fixed


class CltuDecoder:
    """Find CLTUs in a byte stream (one UART) and decode them as bytes arrive.

    ``feed(data)`` returns the decoded data of each CLTU completed by these bytes. Counters:
    ``cltus`` decoded, ``corrected`` bits fixed, ``aborted`` CLTUs dropped on an uncorrectable
    codeblock or an overlong body, ``skipped`` bytes that were not inside a CLTU.
    """

    def __init__(self, derandomize=False, max_blocks=_MAX_BLOCKS):
        self.derandomize = derandomize
        self.max_blocks = max_blocks
        self._buf = bytearray()
        self._data = None  # bytearray while inside a CLTU
        self._fixed = 0
        self.cltus = 0
        self.corrected = 0
        self.aborted = 0
        self.skipped = 0

    def feed(self, data):
        self._buf.extend(data)
        out = []
        buf = self._buf
        pos = 0
        n = len(buf)
        while True:
            if self._data is None:
                i = buf.find(START_SEQUENCE, pos)
                if i < 0:
                    keep = n - 1 if n > pos and buf[n - 1] == 0xEB else n
                    self.skipped += keep - pos
                    pos = keep
                    break
                self.skipped += i - pos
                pos = i + 2
                self._data = bytearray()
                self._fixed = 0
            if n - pos < 8:
                break
            block = buf[pos : pos + 8]
            if block == TAIL_SEQUENCE:
                pos += 8
                data = bytes(self._data)
                self._data = None
                if data:
                    self.cltus += 1
                    self.corrected += self._fixed
                    out.append(randomize_tc(data) if self.derandomize else data)
                else:
                    self.aborted += 1
                continue
            r = correct(block, 0)
            if r < 0 or len(self._data) >= 7 * self.max_blocks:
                # Abandon this CLTU; a new start sequence may begin inside the bad block.
                self.aborted += 1
                self._data = None
                continue
            self._fixed += r
            self._data.extend(block[:7])
            pos += 8
        self._buf = buf[pos:]
        return out
