"""SECDED Hamming(72,64): one check byte per 8 data bytes corrects 1 and detects 2 bit errors.

Check byte: bits 0-6 are the Hamming syndrome bits (the data bits sit at the 64 positions 1..71
that are not powers of two; each check bit covers the positions with its bit set), bit 7 makes
the parity of all 72 bits even. Table driven: 8 lookups per block (tables built on first use).
"""

from obsw.compat import const

BLOCK = const(8)
CODED = const(9)

_tables = []  # [syndrome table (8 x 256), parity table (256), data bit of each position (72)]


class EccError(ValueError):
    """A block with more bit errors than SECDED corrects."""

    def __init__(self, block):
        super().__init__("uncorrectable bit errors in ECC block %d" % block)
        self.block = block


def _build():
    positions = [p for p in range(1, 72) if p & (p - 1)]
    syn = bytearray(8 * 256)
    where = bytearray(b"\xff" * 72)
    for j in range(64):
        where[positions[j]] = j
    for k in range(8):
        for v in range(256):
            s = 0
            for b in range(8):
                if v & (0x80 >> b):
                    s ^= positions[k * 8 + b]
            syn[k * 256 + v] = s
    par = bytearray(256)
    for v in range(256):
        x = v
        x ^= x >> 4
        x ^= x >> 2
        x ^= x >> 1
        par[v] = x & 1
    _tables.append(syn)
    _tables.append(par)
    _tables.append(where)


def _check(buf, off):
    if not _tables:
        _build()
    syn, par = _tables[0], _tables[1]
    s = 0
    p = 0
    for k in range(8):
        v = buf[off + k]
        s ^= syn[(k << 8) | v]
        p ^= par[v]
    return s, p


def check_byte(buf, off=0):
    """The check byte of the 8 data bytes at buf[off:off+8]."""
    s, p = _check(buf, off)
    return s | ((p ^ _tables[1][s]) << 7)


def encode(data):
    """Pad ``data`` with zeros to whole blocks and append a check byte after each block."""
    n = (len(data) + 7) // 8
    out = bytearray(n * CODED)
    for b in range(n):
        o = b * CODED
        chunk = data[b * 8 : b * 8 + 8]
        out[o : o + len(chunk)] = chunk
        out[o + 8] = check_byte(out, o)
    return out


def decode(coded, blocks=None):
    """Return (data, corrected bits); raise EccError on an uncorrectable block."""
    n = len(coded) // CODED if blocks is None else blocks
    out = bytearray(n * BLOCK)
    fixed = 0
    for b in range(n):
        o = b * CODED
        out[b * 8 : b * 8 + 8] = coded[o : o + 8]
        c = coded[o + 8]
        s, p = _check(out, b * 8)
        s ^= c & 0x7F
        p ^= _tables[1][c]  # parity over data and the whole check byte
        if not s and not p:
            continue
        if not p:
            raise EccError(b)
        fixed += 1
        if s and (s & (s - 1)):
            j = _tables[2][s] if s < 72 else 0xFF
            if j == 0xFF:
                raise EccError(b)
            out[b * 8 + (j >> 3)] ^= 0x80 >> (j & 7)
        # s a power of two or 0: a check bit (or the parity bit) flipped; data is fine
    return out, fixed
