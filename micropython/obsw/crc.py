"""CRCs and checksums: CRC-16/CCITT-FALSE (PUS, TC frames) and the CFDP checksum types."""

import struct
from array import array

from obsw.compat import MICROPYTHON, const, crc_accelerator

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

    _RUNNING[crc] = fast
    return crc


# crc function -> its accelerator, which takes the previous value as it is: a running
# checksum (FileChecksum.update, once per file data PDU) calls it without the wrapper
_RUNNING = {}


# Pure definitions: width, polynomial, initial register, reflected, final XOR, check value.
CRC16_CCITT_FALSE = Crc(16, 0x1021, 0xFFFF, False, 0x0000, 0x29B1)
CRC32_IEEE = Crc(32, 0x04C11DB7, 0xFFFFFFFF, True, 0xFFFFFFFF, 0xCBF43926)
CRC32C_CASTAGNOLI = Crc(32, 0x1EDC6F41, 0xFFFFFFFF, True, 0xFFFFFFFF, 0xE3069283)
CRC32_PROXIMITY1 = Crc(32, 0x00A00805, 0x00000000, False, 0x00000000, None)


# --- CRC-16/CCITT-FALSE in pure Python, the packet codecs' hot path ---------------------------
# One table of 256 entries (512 bytes) everywhere. On CPython (never on a board: the tables
# below take 128 KiB and more) two more tricks: a table of 65,536 entries that consumes two
# bytes per step, and for longer inputs the CRC as a linear map of the message bits: bit j of
# the CRC is the parity of (message & PLANE[j]), where PLANE[j] holds bit j of x^(i+16) mod P
# at bit i, so that 16 big-integer ANDs and bit counts replace the loop.
_T1 = array("H", [0] * 256)
for _n in range(256):
    _c = _n << 8
    for _ in range(8):
        _c = ((_c << 1) ^ 0x1021) & 0xFFFF if _c & 0x8000 else (_c << 1) & 0xFFFF
    _T1[_n] = _c
_n = _c = None

_T2 = None  # 16-bit step table (CPython), indexed by register ^ the next two bytes
_WORDS = None  # struct.Struct(">%dH" % k) for k < _NWORDS (CPython)
_NWORDS = const(64)
_PLANES = []  # the 16 bit planes (CPython), covering _PLANE_BITS message bits
_PLANE_BITS = 0
_LONG = const(32)  # from this many bytes on, the bit planes beat the 16-bit table
_CHUNK = const(4096)  # the planes never cover more bytes than this: longer inputs go in chunks
_BIG = not MICROPYTHON
_PLANES_OK = _BIG and hasattr(0, "bit_count")  # int.bit_count: Python 3.10 on


def _make_t2():
    global _T2, _WORDS
    t1 = _T1
    t2 = []
    for hi in range(256):
        a = t1[hi]
        base = (a << 8) & 0xFFFF
        k = a >> 8
        t2.extend([base ^ t1[k ^ lo] for lo in range(256)])  # two message bytes in one step
    _WORDS = [struct.Struct(">%dH" % k) for k in range(_NWORDS)]  # set before _T2 says ready
    _T2 = array("H", t2)
    return _T2


def _grow_planes(nbits):
    global _PLANES, _PLANE_BITS
    nbits = min(max(nbits, 2 * _PLANE_BITS, 1024), _CHUNK * 8)
    rows = []
    r = 0x1021  # x^16 mod P, the weight of the last message bit
    for _ in range(nbits):
        rows.append(bin(r | 0x10000)[3:])  # 16 digits, bit 15 first
        r = ((r << 1) ^ 0x1021) & 0xFFFF if r & 0x8000 else r << 1
    cols = ["".join(col)[::-1] for col in zip(*rows)]  # cols[0] is bit 15
    _PLANES = [int(cols[15 - j], 2) for j in range(16)]
    _PLANE_BITS = nbits


def _crc16_planes(data, reg):
    n = len(data)
    if n > _CHUNK:
        for pos in range(0, n, _CHUNK):
            reg = _crc16_words(data[pos : pos + _CHUNK], reg)
        return reg
    if n * 8 > _PLANE_BITS:
        _grow_planes(n * 8)
    # the register's start value acts as if XORed into the first two message bytes
    d = int.from_bytes(data, "big") ^ (reg << (8 * n - 16))
    p = _PLANES
    return (
        ((d & p[0]).bit_count() & 1)
        | ((d & p[1]).bit_count() & 1) << 1
        | ((d & p[2]).bit_count() & 1) << 2
        | ((d & p[3]).bit_count() & 1) << 3
        | ((d & p[4]).bit_count() & 1) << 4
        | ((d & p[5]).bit_count() & 1) << 5
        | ((d & p[6]).bit_count() & 1) << 6
        | ((d & p[7]).bit_count() & 1) << 7
        | ((d & p[8]).bit_count() & 1) << 8
        | ((d & p[9]).bit_count() & 1) << 9
        | ((d & p[10]).bit_count() & 1) << 10
        | ((d & p[11]).bit_count() & 1) << 11
        | ((d & p[12]).bit_count() & 1) << 12
        | ((d & p[13]).bit_count() & 1) << 13
        | ((d & p[14]).bit_count() & 1) << 14
        | ((d & p[15]).bit_count() & 1) << 15
    )


def _crc16_bytes(data, reg):
    t = _T1
    for b in data:
        reg = ((reg << 8) & 0xFFFF) ^ t[(reg >> 8) ^ b]
    return reg


def _crc16_words(data, reg):
    n = len(data)
    if n >= _LONG and _PLANES_OK:
        return _crc16_planes(data, reg)
    t = _T2 or _make_t2()
    if n & 1:
        reg = ((reg << 8) & 0xFFFF) ^ _T1[(reg >> 8) ^ data[0]]
    k = n >> 1
    if k < _NWORDS:
        words = _WORDS[k].unpack_from(data, n & 1)
    else:
        words = struct.unpack_from(">%dH" % k, data, n & 1)
    for w in words:
        reg = t[reg ^ w]
    return reg


# ``f(data, register)`` with no default: ``crc16_ccitt_update(data, 0xFFFF)`` starts afresh. It
# is binascii.crc_hqx itself where that exists (one Python call less per use than crc16_ccitt).
crc16_ccitt_update = _accel(CRC16_CCITT_FALSE) or (_crc16_words if _BIG else _crc16_bytes)


def crc16_ccitt(data, previous=0xFFFF):
    """CRC-16/CCITT-FALSE of ``data``, continuing ``previous`` (a fresh CRC by default)."""
    return crc16_ccitt_update(data, 0xFFFF if previous is None else previous)


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
            self._crc = _RUNNING.get(self._crc, self._crc)  # value is never None from here
        else:
            raise UnsupportedChecksumError(kind)
        self.kind = kind
        self.offset = 0

    def update(self, data):
        f = self._crc  # a CRC first: the usual kind, once per file data PDU
        if f is not None:
            self.value = f(data, self.value)
        elif self.kind == CHECKSUM_MODULAR:
            self.value = modular(data, self.offset, self.value)
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
