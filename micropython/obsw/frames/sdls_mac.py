"""HMAC-SHA-256 (RFC 2104) on hashlib.sha256, which MicroPython has (its hashlib has no hmac)."""

import hashlib

from obsw.compat import const

_BLOCK = const(64)  # SHA-256 block size, octets
DIGEST_LENGTH = const(32)


class HmacSha256:
    """A keyed HMAC-SHA-256: the padded key blocks are made once, ``digest`` runs per message."""

    __slots__ = ("_inner", "_outer")

    def __init__(self, key):
        key = bytes(key)
        if len(key) > _BLOCK:
            key = hashlib.sha256(key).digest()
        key = key + bytes(_BLOCK - len(key))
        inner = bytearray(_BLOCK)
        outer = bytearray(_BLOCK)
        for i in range(_BLOCK):
            inner[i] = key[i] ^ 0x36
            outer[i] = key[i] ^ 0x5C
        self._inner = bytes(inner)
        self._outer = bytes(outer)

    def digest(self, *parts):
        """The 32-octet MAC of the concatenation of ``parts`` (bytes-like objects)."""
        h = hashlib.sha256(self._inner)
        for p in parts:
            h.update(p)
        h2 = hashlib.sha256(self._outer)
        h2.update(h.digest())
        return h2.digest()


def hmac_sha256(key, message):
    """HMAC-SHA-256 of ``message`` under ``key`` (32 octets)."""
    return HmacSha256(key).digest(message)


def equal(a, b):
    """Compare two MACs in time that depends on their length only, never on where they differ."""
    if len(a) != len(b):
        return False
    diff = 0
    for i in range(len(a)):
        diff |= a[i] ^ b[i]
    return diff == 0
