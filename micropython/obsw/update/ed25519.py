"""Ed25519 signature verification (RFC 8032, section 5.1.7) in Python, for the boards.

``verify(public_key, signature, message)`` is True when ``signature`` (64 bytes) is the
signature of ``message`` by the key whose 32-byte encoding is ``public_key``. It checks
``[S]B = R + [k]A`` (cofactorless) with ``k = SHA-512(R || A || M) mod L``, refuses
``S >= L`` and keys or R that do not decode to a point of the curve, and never raises for a
bad signature; wrong lengths raise ValueError. Points are in extended coordinates and the
two multiplications run in one loop (Shamir's trick). On CPython, ``obsw.update.signature``
takes the ``cryptography`` verifier instead; both give the same answers.
"""

from obsw.update.sha512 import sha512

P = 2**255 - 19
L = 2**252 + 27742317777372353535851937790883648493
D = -121665 * pow(121666, P - 2, P) % P
_SQRT_M1 = pow(2, (P - 1) // 4, P)
_BY = 4 * pow(5, P - 2, P) % P


def _add(p, q):
    x1, y1, z1, t1 = p
    x2, y2, z2, t2 = q
    a = (y1 - x1) * (y2 - x2) % P
    b = (y1 + x1) * (y2 + x2) % P
    c = 2 * D * t1 * t2 % P
    d = 2 * z1 * z2 % P
    e, f, g, h = b - a, d - c, d + c, b + a
    return (e * f % P, g * h % P, f * g % P, e * h % P)


def _double(p):
    x1, y1, z1, _ = p
    a = x1 * x1 % P
    b = y1 * y1 % P
    c = 2 * z1 * z1 % P
    h = a + b
    e = h - (x1 + y1) * (x1 + y1)
    g = a - b
    f = c + g
    return (e * f % P, g * h % P, f * g % P, e * h % P)


def _recover_x(y, sign):
    if y >= P:
        return None
    u = (y * y - 1) % P
    v = (D * y * y + 1) % P
    x = u * pow(v, 3, P) * pow(u * pow(v, 7, P) % P, (P - 5) // 8, P) % P
    vx2 = v * x * x % P
    if vx2 == (P - u) % P:
        x = x * _SQRT_M1 % P
    elif vx2 != u:
        return None
    if x == 0 and sign:
        return None
    if x & 1 != sign:
        x = P - x
    return x


def decode(s):
    """The point of the 32-byte encoding ``s``, or None."""
    y = int.from_bytes(s, "little")
    sign = y >> 255
    y &= (1 << 255) - 1
    x = _recover_x(y, sign)
    if x is None:
        return None
    return (x, y, 1, x * y % P)


def encode(p):
    x, y, z, _ = p
    zi = pow(z, P - 2, P)
    x, y = x * zi % P, y * zi % P
    return (y | ((x & 1) << 255)).to_bytes(32, "little")


BASE = decode(_BY.to_bytes(32, "little"))


def verify(public_key, signature, message):
    """True if ``signature`` is ``public_key``'s signature of ``message`` (see the text)."""
    if len(public_key) != 32 or len(signature) != 64:
        raise ValueError("Ed25519: a 32-byte key and a 64-byte signature, got %d and %d" % (
            len(public_key), len(signature)))  # fmt: skip
    a = decode(public_key)
    r = bytes(signature[:32])
    s = int.from_bytes(signature[32:], "little")
    if a is None or s >= L or decode(r) is None:
        return False
    k = int.from_bytes(sha512(r + bytes(public_key) + bytes(message)), "little") % L
    minus_a = ((P - a[0]) % P, a[1], a[2], (P - a[3]) % P)
    both = _add(BASE, minus_a)
    acc = (0, 1, 1, 0)  # the neutral point
    for i in range(252, -1, -1):  # s, k < L < 2**253
        acc = _double(acc)
        bs, bk = (s >> i) & 1, (k >> i) & 1
        if bs and bk:
            acc = _add(acc, both)
        elif bs:
            acc = _add(acc, BASE)
        elif bk:
            acc = _add(acc, minus_a)
    return encode(acc) == r  # [S]B - [k]A = R
