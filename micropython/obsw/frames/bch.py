"""BCH(63,56) codeblocks of CCSDS 231.0-B: g(x)=x^7+x^6+x^2+1, inverted parity, one filler bit.

A codeblock is 8 bytes: 7 information bytes, then 7 parity bits (complemented) and a zero filler
bit. The decoder corrects any single bit error in the 63 code bits and detects double errors.
"""

from obsw.compat import const

_POLY8 = const(0x8A)  # g(x) without x^7, shifted left once to sit in the top 7 bits of a byte
_G7 = const(0x45)  # x^6 + x^2 + 1: g(x) without its leading term, as a 7-bit register

_tables = []  # [remainder table, syndrome table], built on first use


def _build():
    rem = bytearray(256)
    for i in range(256):
        r = i
        for _ in range(8):
            r = ((r << 1) ^ _POLY8) & 0xFF if r & 0x80 else (r << 1) & 0xFF
        rem[i] = r
    # Syndrome of a single error at degree d is x^d mod g(x); map it to (byte, bit) + 1.
    syn = [0] * 128
    reg = 1
    for d in range(63):
        k = 62 - d  # bit index counted from the first transmitted bit
        syn[reg] = ((k >> 3) << 3 | (7 - (k & 7))) + 1
        reg = ((reg << 1) ^ _G7) & 0x7F if reg & 0x40 else reg << 1
    _tables.append(rem)
    _tables.append(syn)


def parity(info, offset=0):
    """Return the parity byte (complemented parity bits, filler bit 0) of 7 information bytes."""
    if not _tables:
        _build()
    rem = _tables[0]
    r = 0
    for i in range(offset, offset + 7):
        r = rem[info[i] ^ r]
    return (r ^ 0xFF) & 0xFE


def encode_block(info):
    """Return the 8-byte codeblock for exactly 7 information bytes."""
    if len(info) != 7:
        raise ValueError("BCH codeblock needs 7 information bytes, got %d" % len(info))
    return bytes(info) + bytes((parity(info),))


def correct(block, offset=0):
    """Check one codeblock in place (a bytearray); fix a single bit error.

    Returns 0 if the block was clean, 1 if a bit was corrected, -1 if it is uncorrectable.
    The filler bit is not part of the code and is not checked.
    """
    if not _tables:
        _build()
    rem = _tables[0]
    r = 0
    for i in range(offset, offset + 7):
        r = rem[block[i] ^ r]
    s = ((r ^ block[offset + 7] ^ 0xFF) >> 1) & 0x7F
    if s == 0:
        return 0
    pos = _tables[1][s]
    if not pos:
        return -1
    pos -= 1
    block[offset + (pos >> 3)] ^= 1 << (pos & 7)
    return 1
