"""CCSDS pseudo-randomizers: TM (131.0-B, h(x)=x^8+x^7+x^5+x^3+1) and TC (231.0-B)."""

from obsw.compat import const

_PERIOD = const(255)
_cache = {}


def _sequence(taps):
    # Fibonacci LFSR seeded with all ones; the output bit is the register's oldest stage.
    seq = _cache.get(taps)
    if seq is not None:
        return seq
    reg = 0xFF
    out = bytearray(_PERIOD)
    for i in range(_PERIOD):
        byte = 0
        for _ in range(8):
            byte = (byte << 1) | (reg & 1)
            fb = 0
            for t in taps:
                fb ^= reg >> t
            reg = (reg >> 1) | ((fb & 1) << 7)
        out[i] = byte
    seq = bytes(out)
    _cache[taps] = seq
    return seq


def tm_sequence():
    """The 255-byte TM pseudo-random sequence (starts FF 48 0E C0 9A)."""
    return _sequence((0, 3, 5, 7))


def tc_sequence():
    """The 255-byte TC pseudo-random sequence, x^8+x^6+x^4+x^3+x^2+x+1 (starts FF 39 9E 5A)."""
    return _sequence((0, 1, 2, 3, 4, 6))


def _xor(data, seq):
    out = bytearray(data)
    n = len(out)
    i = 0
    while i < n:
        end = min(n, i + _PERIOD)
        for j in range(i, end):
            out[j] ^= seq[j - i]
        i = end
    return bytes(out)


def randomize_tm(data):
    """XOR ``data`` with the TM sequence; the same call derandomizes."""
    return _xor(data, tm_sequence())


def randomize_tc(data):
    """XOR ``data`` with the TC sequence; the same call derandomizes."""
    return _xor(data, tc_sequence())
