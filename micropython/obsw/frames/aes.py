"""AES encryption (FIPS 197) in Python: the block function where neither cryptolib nor
cryptography is there (a board image built without cryptolib). Encryption only: GCM and CTR
never decrypt a block. Byte-oriented, so that every value is a small int (no big-int tables
on a 32-bit board); the two 256-octet tables are made on first use, not at import.
"""

_T = []  # [sbox, xtime] once made
_SHIFT = bytes((0, 5, 10, 15, 4, 9, 14, 3, 8, 13, 2, 7, 12, 1, 6, 11))  # ShiftRows, column-major


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
    xtime = bytes(((i << 1) ^ (0x1B if i & 0x80 else 0)) & 0xFF for i in range(256))
    _T.extend((bytes(sbox), xtime))
    return _T


class Aes:
    """AES under ``key`` (16, 24 or 32 octets); ``encrypt(data)`` takes whole blocks (ECB)."""

    def __init__(self, key):
        key = bytes(key)
        if len(key) not in (16, 24, 32):
            raise ValueError("AES key of %d octets, expected 16, 24 or 32" % len(key))
        sbox, xtime = _tables()
        nk = len(key) // 4
        self._rounds = nk + 6
        w = bytearray(16 * (self._rounds + 1))
        w[: len(key)] = key
        rcon = 1
        for i in range(nk, 4 * (self._rounds + 1)):
            t = w[4 * i - 4 : 4 * i]
            if i % nk == 0:
                t = bytearray((sbox[t[1]] ^ rcon, sbox[t[2]], sbox[t[3]], sbox[t[0]]))
                rcon = xtime[rcon]
            elif nk > 6 and i % nk == 4:
                t = bytearray((sbox[t[0]], sbox[t[1]], sbox[t[2]], sbox[t[3]]))
            for j in range(4):
                w[4 * i + j] = w[4 * (i - nk) + j] ^ t[j]
        self._w = bytes(w)

    def encrypt(self, data):
        sbox, xtime = _tables()
        w = self._w
        nr = self._rounds
        shift = _SHIFT
        out = bytearray(len(data))
        s = bytearray(16)
        for off in range(0, len(data), 16):
            for i in range(16):
                s[i] = data[off + i] ^ w[i]
            k = 16
            for _ in range(nr - 1):
                t = bytes(sbox[s[j]] for j in shift)  # SubBytes and ShiftRows
                for c in range(0, 16, 4):  # MixColumns and AddRoundKey
                    a0 = t[c]
                    a1 = t[c + 1]
                    a2 = t[c + 2]
                    a3 = t[c + 3]
                    x = a0 ^ a1 ^ a2 ^ a3
                    s[c] = a0 ^ x ^ xtime[a0 ^ a1] ^ w[k + c]
                    s[c + 1] = a1 ^ x ^ xtime[a1 ^ a2] ^ w[k + c + 1]
                    s[c + 2] = a2 ^ x ^ xtime[a2 ^ a3] ^ w[k + c + 2]
                    s[c + 3] = a3 ^ x ^ xtime[a3 ^ a0] ^ w[k + c + 3]
                k += 16
            for i in range(16):
                out[off + i] = sbox[s[shift[i]]] ^ w[k + i]
        return bytes(out)
