"""AES encryption (FIPS 197) in Python: the block function where neither cryptolib nor
cryptography is there (a board image built without cryptolib). Encryption only: GCM and CTR
never decrypt a block. Tables are made on first use, not at import.
"""

_T = []  # [sbox, te0, te1, te2, te3] once made


def _tables():
    if _T:
        return _T
    sbox = bytearray(256)
    p = q = 1
    while True:  # walk the multiplicative group with generator 3, its inverse with 0xF6
        p = p ^ ((p << 1) & 0xFF) ^ (0x1B if p & 0x80 else 0)
        q ^= q << 1
        q ^= q << 2
        q ^= q << 4
        q &= 0xFF
        if q & 0x80:
            q ^= 0x09
        x = q ^ ((q << 1 | q >> 7) & 0xFF) ^ ((q << 2 | q >> 6) & 0xFF)
        x ^= ((q << 3 | q >> 5) & 0xFF) ^ ((q << 4 | q >> 4) & 0xFF)
        sbox[p] = x ^ 0x63
        if p == 1:
            break
    sbox[0] = 0x63
    te0 = [0] * 256
    for i in range(256):
        s = sbox[i]
        s2 = ((s << 1) ^ (0x1B if s & 0x80 else 0)) & 0xFF
        te0[i] = (s2 << 24) | (s << 16) | (s << 8) | (s2 ^ s)
    te1 = [(t >> 8) | ((t & 0xFF) << 24) for t in te0]
    te2 = [(t >> 8) | ((t & 0xFF) << 24) for t in te1]
    te3 = [(t >> 8) | ((t & 0xFF) << 24) for t in te2]
    _T.extend((bytes(sbox), te0, te1, te2, te3))
    return _T


class Aes:
    """AES under ``key`` (16, 24 or 32 octets); ``encrypt(data)`` takes whole blocks (ECB)."""

    def __init__(self, key):
        key = bytes(key)
        nk = len(key) // 4
        if len(key) not in (16, 24, 32):
            raise ValueError("AES key of %d octets, expected 16, 24 or 32" % len(key))
        sbox = _tables()[0]
        self._rounds = nk + 6
        w = [int.from_bytes(key[4 * i : 4 * i + 4], "big") for i in range(nk)]
        rcon = 1
        for i in range(nk, 4 * (self._rounds + 1)):
            t = w[i - 1]
            if i % nk == 0:
                t = ((t << 8) & 0xFFFFFFFF) | (t >> 24)
                t = _sub(sbox, t) ^ (rcon << 24)
                rcon = ((rcon << 1) ^ (0x1B if rcon & 0x80 else 0)) & 0xFF
            elif nk > 6 and i % nk == 4:
                t = _sub(sbox, t)
            w.append(w[i - nk] ^ t)
        self._w = w

    def encrypt(self, data):
        sbox, te0, te1, te2, te3 = _tables()
        w = self._w
        nr = self._rounds
        out = bytearray(len(data))
        for off in range(0, len(data), 16):
            s0 = int.from_bytes(data[off : off + 4], "big") ^ w[0]
            s1 = int.from_bytes(data[off + 4 : off + 8], "big") ^ w[1]
            s2 = int.from_bytes(data[off + 8 : off + 12], "big") ^ w[2]
            s3 = int.from_bytes(data[off + 12 : off + 16], "big") ^ w[3]
            k = 4
            for _ in range(nr - 1):
                t0 = te0[s0 >> 24] ^ te1[(s1 >> 16) & 255] ^ te2[(s2 >> 8) & 255] ^ te3[s3 & 255]
                t1 = te0[s1 >> 24] ^ te1[(s2 >> 16) & 255] ^ te2[(s3 >> 8) & 255] ^ te3[s0 & 255]
                t2 = te0[s2 >> 24] ^ te1[(s3 >> 16) & 255] ^ te2[(s0 >> 8) & 255] ^ te3[s1 & 255]
                t3 = te0[s3 >> 24] ^ te1[(s0 >> 16) & 255] ^ te2[(s1 >> 8) & 255] ^ te3[s2 & 255]
                s0 = t0 ^ w[k]
                s1 = t1 ^ w[k + 1]
                s2 = t2 ^ w[k + 2]
                s3 = t3 ^ w[k + 3]
                k += 4
            for j, (a, b, c, d) in enumerate(((s0, s1, s2, s3), (s1, s2, s3, s0),
                                               (s2, s3, s0, s1), (s3, s0, s1, s2))):  # fmt: skip
                v = (sbox[a >> 24] << 24) | (sbox[(b >> 16) & 255] << 16)
                v |= (sbox[(c >> 8) & 255] << 8) | sbox[d & 255]
                out[off + 4 * j : off + 4 * j + 4] = (v ^ w[k + j]).to_bytes(4, "big")
        return bytes(out)


def _sub(sbox, t):
    return (
        (sbox[t >> 24] << 24)
        | (sbox[(t >> 16) & 255] << 16)
        | (sbox[(t >> 8) & 255] << 8)
        | (sbox[t & 255])
    )
