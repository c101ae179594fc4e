"""AES-GCM and GMAC (NIST SP 800-38D), the SDLS baseline cipher suite (CCSDS 355.0-B-2, 352.0).

The AES block function comes from ``obsw.compat.aes_ecb`` (``cryptolib`` on MicroPython,
``cryptography`` on CPython); counter mode and GHASH are here. GHASH multiplies in GF(2^128)
four bits at a time (Shoup's table of the 16 multiples of H, made once per key). On CPython,
``cryptography``'s AESGCM does the whole operation in C when the tag is full length; both paths
give the same octets (tests/core/test_frames_gcm.py).
"""

from obsw.compat import aes_ecb, const, gcm_accelerator

TAG_LENGTH = const(16)
IV_LENGTH = const(12)  # the recommended IV length, and the SDLS baseline
_R = 0xE1 << 120  # x^128 = x^7 + x^2 + x + 1, in GCM's reflected bit order
_MASK32 = 0xFFFFFFFF  # not a const: above the small ints of 32-bit ports


class GcmError(ValueError):
    """A key, IV or tag length GCM does not take."""


class GcmAuthError(ValueError):
    """The tag does not match: the data, the AAD, the IV or the key differ from the sender's."""


def _mul_x4(v):
    """``v`` times x^4 (four right shifts with reduction), for small ``v`` (the table)."""
    for _ in range(4):
        v = (v >> 1) ^ _R if v & 1 else v >> 1
    return v


_REDUCE = tuple(_mul_x4(i) for i in range(16))


def _int(b):
    return int.from_bytes(b, "big")


class AesGcm:
    """AES-GCM under one key (16, 24 or 32 octets). ``encrypt`` and ``decrypt`` take the IV,
    the data and the additional authenticated data (AAD); ``tag_length`` 4..16 octets."""

    __slots__ = ("_ecb", "_table", "_fast")

    def __init__(self, key):
        key = bytes(key)
        if len(key) not in (16, 24, 32):
            raise GcmError("AES key of %d octets, expected 16, 24 or 32" % len(key))
        self._fast = gcm_accelerator(key)
        self._ecb = aes_ecb(key)
        h = _int(self._ecb(bytes(16)))
        table = [0] * 16
        # table[n] = n(x) * H, nibble bit 8 the coefficient of x^0 ... bit 1 that of x^3
        v = h
        for bit in (8, 4, 2, 1):
            table[bit] = v
            v = (v >> 1) ^ _R if v & 1 else v >> 1
        for n in range(16):
            if n & (n - 1):
                low = n & -n
                table[n] = table[low] ^ table[n ^ low]
        self._table = tuple(table)

    def _mul_h(self, y):
        t = self._table
        r = _REDUCE
        z = t[y & 15]
        y >>= 4
        for _ in range(31):
            z = (z >> 4) ^ r[z & 15] ^ t[y & 15]
            y >>= 4
        return z

    def _ghash(self, y, data):
        """Continue GHASH state ``y`` over ``data`` zero-padded to whole blocks."""
        n = len(data)
        full = n - n % 16
        for i in range(0, full, 16):
            y = self._mul_h(y ^ _int(data[i : i + 16]))
        if full < n:
            y = self._mul_h(y ^ (_int(data[full:]) << (8 * (16 - n + full))))
        return y

    def _j0(self, iv):
        if len(iv) == IV_LENGTH:
            return _int(iv) << 32 | 1
        if not iv:
            raise GcmError("empty GCM IV")
        y = self._ghash(0, iv)
        return self._mul_h(y ^ (len(iv) * 8))

    def _ctr(self, j0, data):
        """``data`` XOR the key stream that starts at counter block inc32(J0)."""
        n = len(data)
        if not n:
            return b""
        blocks = (n + 15) // 16
        high = j0 & ~_MASK32
        low = j0 & _MASK32
        counters = bytearray(16 * blocks)
        for i in range(blocks):
            counters[16 * i : 16 * i + 16] = (high | ((low + 1 + i) & _MASK32)).to_bytes(16, "big")
        stream = self._ecb(bytes(counters))
        return (_int(data) ^ _int(stream[:n])).to_bytes(n, "big")

    def _tag(self, j0, aad, ciphertext, tag_length):
        y = self._ghash(self._ghash(0, aad), ciphertext)
        y = self._mul_h(y ^ (len(aad) * 8 << 64 | len(ciphertext) * 8))
        s = _int(self._ecb(j0.to_bytes(16, "big"))) ^ y
        return s.to_bytes(16, "big")[:tag_length]

    @staticmethod
    def _check_tag_length(tag_length):
        if not 4 <= tag_length <= TAG_LENGTH:
            raise GcmError("GCM tag of %d octets, expected 4..16" % tag_length)

    def encrypt(self, iv, data, aad=b"", tag_length=TAG_LENGTH):
        """(ciphertext, tag) of ``data`` under ``iv`` with ``aad`` authenticated."""
        self._check_tag_length(tag_length)
        iv = bytes(iv)
        if self._fast is not None and tag_length == TAG_LENGTH and len(iv) >= 8:
            out = self._fast.encrypt(iv, bytes(data), bytes(aad))
            return out[:-TAG_LENGTH], out[-TAG_LENGTH:]
        j0 = self._j0(iv)
        ciphertext = self._ctr(j0, bytes(data))
        return ciphertext, self._tag(j0, bytes(aad), ciphertext, tag_length)

    def decrypt(self, iv, ciphertext, tag, aad=b""):
        """The plaintext of ``ciphertext``; GcmAuthError when ``tag`` does not verify."""
        tag = bytes(tag)
        self._check_tag_length(len(tag))
        iv = bytes(iv)
        if self._fast is not None and len(tag) == TAG_LENGTH and len(iv) >= 8:
            try:
                return self._fast.decrypt(iv, bytes(ciphertext) + tag, bytes(aad))
            except Exception:  # cryptography's InvalidTag
                raise GcmAuthError("GCM tag does not verify") from None
        j0 = self._j0(iv)
        ciphertext = bytes(ciphertext)
        if not equal(self._tag(j0, bytes(aad), ciphertext, len(tag)), tag):
            raise GcmAuthError("GCM tag does not verify")
        return self._ctr(j0, ciphertext)

    def gmac(self, iv, aad, tag_length=TAG_LENGTH):
        """GMAC: the tag of ``aad`` alone (authentication without encryption)."""
        return self.encrypt(iv, b"", aad, tag_length)[1]


def equal(a, b):
    """Compare two tags in time that depends on their length only."""
    if len(a) != len(b):
        return False
    diff = 0
    for i in range(len(a)):
        diff |= a[i] ^ b[i]
    return diff == 0
