"""Ed25519 signature verification (RFC 8032 section 5.1.7) in Python, for the reconfiguration
module's Cortex-M4 and any interpreter without a C implementation.

    from obsw.update.ed25519 import verify
    verify(public_key, signature, message)   # True or False

The check is the cofactorless one, ``[S]B == R + [k]A``, computed as ``[S]B + [k](-A)`` and
compared with R's 32 octets, and it is strict: S must be below the group order L, and the public
key must be a canonical encoding (y below p, no "negative zero" x) of a point on the curve. An R
that is not a canonical encoding of a point never equals the canonical encoding of the point
computed, so it is refused the same way. The arithmetic is in extended twisted Edwards
coordinates (Hisil, Wong, Carter and Dawson, 2008, with a = -1), both scalars in width-5
non-adjacent form over one shared chain of doublings, and one inversion at the end.
"""

from obsw.compat import const, micropython
from obsw.update.sha512 import sha512

_P = const(2**255 - 19)
_L = const(2**252 + 27742317777372353535851937790883648493)
_D = const(37095705934669439343138083508754565189542113879843219016388785533085940283555)
_D2 = const(16295367250680780974490674513165176452449235426866156013048779062215315747161)
_SQRT_M1 = const(19681161376707505956807079304988542015446066515923890162744021073123829784752)
_BX = const(15112221349535400772501151409588531511454012693041857206046113283949847762202)
_BY = const(46316835694926478169428394003475163141307993866256225615783033603165251855960)
_W = const(5)  # the NAF width: 8 odd multiples of each base, one addition every 6 doublings


@micropython.native
def _double(x1, y1, z1, with_t):
    """2P (dbl-2008-hwcd, a = -1); T only when an addition follows."""
    a = x1 * x1 % _P
    b = y1 * y1 % _P
    c = 2 * z1 * z1 % _P
    h = a + b
    s = x1 + y1
    e = h - s * s % _P
    g = a - b
    f = c + g
    return (
        e * f % _P,
        g * h % _P,
        f * g % _P,
        e * h % _P if with_t else 0,
    )


@micropython.native
def _add(x1, y1, z1, t1, q, negate):
    """P + Q, or P - Q when ``negate``; Q cached as (Y+X, Y-X, 2Z, 2dT) (add-2008-hwcd-3)."""
    if negate:
        a = (y1 - x1) * q[0] % _P
        b = (y1 + x1) * q[1] % _P
        c = -t1 * q[3] % _P
    else:
        a = (y1 - x1) * q[1] % _P
        b = (y1 + x1) * q[0] % _P
        c = t1 * q[3] % _P
    d = z1 * q[2] % _P
    e = b - a
    f = d - c
    g = d + c
    h = b + a
    return e * f % _P, g * h % _P, f * g % _P, e * h % _P


def _cached(x, y, z, t):
    return ((y + x) % _P, (y - x) % _P, 2 * z % _P, _D2 * t % _P)


def _odd_multiples(x, y, z, t):
    """P, 3P, 5P, ... (2**(W-1) - 1)P, cached for addition."""
    first = _cached(x, y, z, t)
    table = [first]
    twice = _cached(*_double(x, y, z, True))
    for _ in range(1, 1 << (_W - 2)):
        x, y, z, t = _add(x, y, z, t, twice, False)
        table.append(_cached(x, y, z, t))
    return table


def _naf(k):
    """The width-W non-adjacent form of ``k``, least significant digit first."""
    digits = []
    window = 1 << _W
    half = window >> 1
    while k:
        if k & 1:
            digit = k & (window - 1)
            if digit >= half:
                digit -= window
            k -= digit
        else:
            digit = 0
        digits.append(digit)
        k >>= 1
    return digits


def canonical_encoding(octets):
    """False for the encodings RFC 8032 section 5.1.3 refuses whatever the curve: y not below p,
    and x = 0 (y = 1 or p - 1) with the sign bit set."""
    y = int.from_bytes(octets, "little")
    sign = y >> 255
    y &= (1 << 255) - 1
    return y < _P and not (sign and (y == 1 or y == _P - 1))


def _decode(octets):
    """The point of a canonical encoding (RFC 8032 section 5.1.3) as (x, y), or None."""
    if not canonical_encoding(octets):
        return None
    y = int.from_bytes(octets, "little")
    sign = y >> 255
    y &= (1 << 255) - 1
    yy = y * y % _P
    u = (yy - 1) % _P
    v = (_D * yy + 1) % _P
    v3 = v * v % _P * v % _P
    x = u * v3 % _P * pow(u * v3 % _P * v3 % _P * v % _P, (_P - 5) // 8, _P) % _P
    vxx = v * x % _P * x % _P
    if vxx != u:
        if vxx != _P - u:
            return None  # no square root: not on the curve
        x = x * _SQRT_M1 % _P
    if x & 1 != sign:
        x = _P - x
    return x, y


def check_lengths(public_key, signature):
    if len(public_key) != 32:
        raise ValueError("an Ed25519 public key is 32 octets, not %d" % len(public_key))
    if len(signature) != 64:
        raise ValueError("an Ed25519 signature is 64 octets, not %d" % len(signature))


def verify(public_key, signature, message):
    """True when ``signature`` (64 octets) is ``public_key``'s (32 octets) over ``message``.

    Any octets of the right lengths give True or False; wrong lengths raise ValueError."""
    check_lengths(public_key, signature)
    public_key = bytes(public_key)
    signature = bytes(signature)
    s = int.from_bytes(signature[32:], "little")
    if s >= _L:
        return False
    a = _decode(public_key)
    if a is None:
        return False
    k = int.from_bytes(sha512(signature[:32] + public_key + bytes(message)), "little") % _L
    ax = _P - a[0]  # -A: k is added with A negated
    a_table = _odd_multiples(ax, a[1], 1, ax * a[1] % _P)
    b_table = _odd_multiples(_BX, _BY, 1, _BX * _BY % _P)
    s_naf = _naf(s)
    k_naf = _naf(k)
    n = max(len(s_naf), len(k_naf))
    s_naf += [0] * (n - len(s_naf))
    k_naf += [0] * (n - len(k_naf))
    x, y, z, t = 0, 1, 1, 0
    for i in range(n - 1, -1, -1):
        ds = s_naf[i]
        dk = k_naf[i]
        if ds:
            x, y, z, t = _add(x, y, z, t, b_table[abs(ds) >> 1], ds < 0)
        if dk:
            x, y, z, t = _add(x, y, z, t, a_table[abs(dk) >> 1], dk < 0)
        if i:
            x, y, z, t = _double(x, y, z, s_naf[i - 1] or k_naf[i - 1])
    zi = pow(z, _P - 2, _P)
    x = x * zi % _P
    y = y * zi % _P
    return (y | (x & 1) << 255).to_bytes(32, "little") == signature[:32]
