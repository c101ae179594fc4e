"""Convolutional code of CCSDS 131.0-B: rate 1/2, K=7, G1=171 and G2=133 (octal), G2 inverted."""

from obsw.compat import const

# The generators as masks of a register holding the current input bit in bit 0 and the bit of
# i symbols ago in bit i: 171 octal (1111001, current bit first) taps delays 0,1,2,3,6 and
# 133 octal (1011011) taps delays 0,2,3,5,6.
G1 = const(0x4F)
G2 = const(0x6D)
K = const(7)
_INVERT = const(0x5555)  # the G2 symbol of each pair is inverted (131.0-B 3.3)

_tables = []


def _parity(x):
    x ^= x >> 4
    x ^= x >> 2
    x ^= x >> 1
    return x & 1


def _lin(state, byte):
    # The 16 output symbols (C1 C2 per input bit, first bit in the top pair) of one input octet
    # after ``state`` (the last six bits, newest in bit 0), before the G2 inversion.
    reg = state
    out = 0
    for i in range(7, -1, -1):
        reg = ((reg << 1) | ((byte >> i) & 1)) & 0x7F
        out = (out << 2) | (_parity(reg & G1) << 1) | _parity(reg & G2)
    return out


def _encoder_tables():
    # The code is linear over GF(2): the symbols of an octet are the state's part XOR the
    # octet's part, so 64 + 256 entries stand for the 16384 (state, octet) pairs.
    if not _tables:
        _tables.append([_lin(s, 0) for s in range(64)])
        _tables.append([_lin(0, b) ^ _INVERT for b in range(256)])
    return _tables


def branch_symbols(state, bit):
    """The transmitted symbols (C1, C2) for input ``bit`` after ``state`` (G2 inverted)."""
    reg = ((state << 1) | bit) & 0x7F
    return _parity(reg & G1), _parity(reg & G2) ^ 1


class ConvEncoder:
    """The onboard encoder: a continuous stream, its state carried from one ``encode`` call to
    the next (131.0-B does not terminate the code between frames); two octets per octet."""

    def __init__(self, state=0):
        self.state = state & 0x3F

    def encode(self, data):
        ta, tb = _encoder_tables()
        out = bytearray(2 * len(data))
        s = self.state
        i = 0
        for b in data:
            o = ta[s] ^ tb[b]
            out[i] = o >> 8
            out[i + 1] = o & 0xFF
            i += 2
            s = b & 0x3F
        self.state = s
        return bytes(out)
