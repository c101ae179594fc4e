"""CRCs and checksums: CRC-16/CCITT-FALSE (PUS, TC frames) and the CFDP checksum types."""

import struct
from array import array

from obsw.compat import const, crc_accelerator

# CFDP checksum type identifiers (SANA checksum identifiers registry, CCSDS 727.0-B-5).
CHECKSUM_MODULAR = const(0)
CHECKSUM_PROXIMITY1 = const(1)
CHECKSUM_CRC32C = const(2)
CHECKSUM_CRC32 = const(3)
CHECKSUM_NULL = const(15)


class UnsupportedChecksumError(ValueError):
    """A checksum type this entity does not implement (CFDP condition 'unsupported checksum')."""

    def __init__(self, kind):
        super().__init__("unsupported checksum type %r" % (kind,))
        self.kind = kind


class Crc:
    """A table-driven CRC in pure Python; ``crc(data, previous)`` continues a running value.

    ``previous`` is a value this function returned earlier (or ``start`` for a fresh one), so
    ``crc(b, crc(a)) == crc(a + b)`` whatever the final XOR.
    """

    def __init__(self, width, poly, init, reflect, xorout, check):
        self.width = width
        self.poly = poly
        self.reflect = reflect
        self.xorout = xorout
        self.start = init ^ xorout
        self.check = check  # CRC of b"123456789", the catalogue's check value
        self._table = None

    def _make_table(self):
        mask = (1 << self.width) - 1
        table = array("I", [0] * 256)
        if self.reflect:
            rpoly = 0
            for i in range(self.width):
                if self.poly >> i & 1:
                    rpoly |= 1 << (self.width - 1 - i)
            for n in range(256):
                c = n
                for _ in range(8):
                    c = (c >> 1) ^ rpoly if c & 1 else c >> 1
                table[n] = c
        else:
            top = 1 << (self.width - 1)
            for n in range(256):
                c = n << (self.width - 8)
                for _ in range(8):
                    c = ((c << 1) ^ self.poly) & mask if c & top else (c << 1) & mask
                table[n] = c
        self._table = table
        return table

    def __call__(self, data, previous=None):
        table = self._table or self._make_table()
        reg = (self.start if previous is None else previous) ^ self.xorout
        if self.reflect:
            for b in data:
                reg = (reg >> 8) ^ table[(reg ^ b) & 0xFF]
        elif self.width == 16:
            for b in data:
                reg = ((reg << 8) & 0xFFFF) ^ table[(reg >> 8) ^ b]
        else:
            shift = self.width - 8
            mask = (1 << self.width) - 1
            for b in data:
                reg = ((reg << 8) & mask) ^ table[((reg >> shift) ^ b) & 0xFF]
        return reg ^ self.xorout


def _accel(spec):
    return crc_accelerator(
        spec.width, spec.poly, spec.start ^ spec.xorout, spec.reflect, spec.xorout
    )


def _fast(spec):
    """The C accelerator for ``spec`` when the interpreter has one, else the pure function."""
    fast = _accel(spec)
    if fast is None:
        return spec
    start = spec.start

    def crc(data, previous=None):
        return fast(data, start if previous is None else previous)

    return crc


# Pure definitions: width, polynomial, initial register, reflected, final XOR, check value.
CRC16_CCITT_FALSE = Crc(16, 0x1021, 0xFFFF, False, 0x0000, 0x29B1)
CRC32_IEEE = Crc(32, 0x04C11DB7, 0xFFFFFFFF, True, 0xFFFFFFFF, 0xCBF43926)
CRC32C_CASTAGNOLI = Crc(32, 0x1EDC6F41, 0xFFFFFFFF, True, 0xFFFFFFFF, 0xE3069283)
CRC32_PROXIMITY1 = Crc(32, 0x00A00805, 0x00000000, False, 0x00000000, None)

crc16_ccitt = _fast(CRC16_CCITT_FALSE)
# The same CRC as ``f(data, register)`` with no default: ``crc16_ccitt_update(data, 0xFFFF)``
# starts afresh. It is binascii.crc_hqx itself where that exists, one Python call less per use
# than crc16_ccitt (the packet codecs' hot path).
crc16_ccitt_update = _accel(CRC16_CCITT_FALSE) or CRC16_CCITT_FALSE
crc32 = _fast(CRC32_IEEE)
crc32c = _fast(CRC32C_CASTAGNOLI)
crc32_proximity1 = _fast(CRC32_PROXIMITY1)


def modular(data, offset=0, previous=0):
    """CFDP modular checksum: 32-bit words aligned to file offsets, summed modulo 2**32.

    ``offset`` is the file offset of ``data[0]``; segments may be added in any order.
    """
    total = previous
    mv = memoryview(data)
    pos = 0
    size = len(data)
    while pos < size:
        # work in bounded chunks so a board never builds a huge tuple
        chunk = mv[pos : pos + 1024]
        lead = (offset + pos) & 3
        buf = bytes(lead) + bytes(chunk) if lead else bytes(chunk)
        tail = -len(buf) & 3
        if tail:
            buf += bytes(tail)
        for w in struct.unpack(">%dI" % (len(buf) >> 2), buf):
            total += w
        total &= 0xFFFFFFFF
        pos += len(chunk)
    return total


class FileChecksum:
    """Running checksum of a file's bytes in order, for any CFDP checksum type."""

    def __init__(self, kind):
        if kind == CHECKSUM_MODULAR:
            self._crc = None
            self.value = 0
        elif kind == CHECKSUM_NULL:
            self._crc = None
            self.value = 0
        elif kind in _CFDP_CRCS:
            self._crc = _CFDP_CRCS[kind]
            self.value = self._crc(b"")
        else:
            raise UnsupportedChecksumError(kind)
        self.kind = kind
        self.offset = 0

    def update(self, data):
        if self.kind == CHECKSUM_MODULAR:
            self.value = modular(data, self.offset, self.value)
        elif self._crc is not None:
            self.value = self._crc(data, self.value)
        self.offset += len(data)
        return self


_CFDP_CRCS = {
    CHECKSUM_PROXIMITY1: crc32_proximity1,
    CHECKSUM_CRC32C: crc32c,
    CHECKSUM_CRC32: crc32,
}


def checksum(kind, data):
    """Checksum of a whole byte string with a CFDP checksum type."""
    return FileChecksum(kind).update(data).value
