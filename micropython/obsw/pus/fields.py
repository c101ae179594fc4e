"""ECSS-E-ST-70-41C packet field types (clause 7.3): PTC/PFC lookup and the numeric types.

``field(ptc, pfc, **mission)`` returns a field type with ``write(encoder, value)``,
``read(decoder)``, ``pack(value)`` and ``unpack(buf)``. The numeric types (PTC 1-5) live here;
strings and packets in ``obsw.pus.ptc_strings``, times in ``obsw.pus.ptc_time``, structures,
repeated groups and deduced fields in ``obsw.pus.structure``.
"""

import math

from obsw.bits import BitsValueError, Decoder, Encoder
from obsw.compat import const

PTC_BOOLEAN = const(1)
PTC_ENUMERATED = const(2)
PTC_UNSIGNED = const(3)
PTC_SIGNED = const(4)
PTC_REAL = const(5)
PTC_BIT_STRING = const(6)
PTC_OCTET_STRING = const(7)
PTC_CHARACTER_STRING = const(8)
PTC_ABSOLUTE_TIME = const(9)
PTC_RELATIVE_TIME = const(10)
PTC_DEDUCED = const(11)
PTC_PACKET = const(12)

# Unsigned and signed integer PFC -> width in bits (same table for PTC 3 and 4; PFC 17-19,
# the widths below 4 bits, are defined for unsigned integers only).
INTEGER_BITS = (4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 24, 32, 48, 64, 1, 2, 3)
_SIGNED_PFC_MAX = const(16)
# Enumerated: the PFC is the width in bits.
ENUMERATED_PFCS = tuple(range(1, 17)) + (24, 32, 48, 64)

REAL_IEEE_SINGLE = const(1)
REAL_IEEE_DOUBLE = const(2)
REAL_MIL_SIMPLE = const(3)
REAL_MIL_EXTENDED = const(4)

_INT_FMT = {8: "B", 16: "H", 32: "I", 64: "Q"}
_FLT_MAX = 3.4028234663852886e38
# not math.inf in the code: the compiler folds it into a constant that the freezer writes as
# C 'inf', which does not compile (frozen images)
_INF = float("inf")


class FieldTypeError(ValueError):
    """A PTC/PFC pair the standard does not define (or a bad mission parameter)."""

    def __init__(self, ptc, pfc, why=""):
        msg = "no packet field type PTC %r PFC %r" % (ptc, pfc)
        super().__init__(msg + (": " + why if why else ""))
        self.ptc = ptc
        self.pfc = pfc


class FieldValueError(ValueError):
    """A value a field cannot carry (encoding) or content a field cannot hold (decoding)."""

    def __init__(self, field, value, expected):
        super().__init__("%s: %s expected, got %r" % (field, expected, value))
        self.field = field
        self.value = value
        self.expected = expected


class FieldType:
    """Base of all field types: ``bits`` is the fixed width, or None when variable."""

    ptc = 0
    pfc = 0
    bits = None
    fmt = None  # struct code when the field is a whole big-endian C type (B H I Q b h i q f d)
    name = "field"

    def __repr__(self):
        return "<PTC %d PFC %d %s>" % (self.ptc, self.pfc, self.name)

    @property
    def label(self):
        return "PTC %d PFC %d (%s)" % (self.ptc, self.pfc, self.name)

    def fail(self, value, expected):
        raise FieldValueError(self.label, value, expected)

    def check(self, value):
        """Raise FieldValueError unless ``value`` can be written (and return it normalised)."""
        return value

    def write(self, enc, value):
        raise NotImplementedError

    def read(self, dec):
        raise NotImplementedError

    def pack(self, value):
        enc = Encoder()
        self.write(enc, value)
        return enc.getvalue()

    def unpack(self, buf, bit_offset=0):
        """The value at the start of ``buf`` (trailing bytes are left alone)."""
        return self.read(Decoder(buf, bit_offset))


class Boolean(FieldType):
    """PTC 1: 0 is False, anything else True."""

    ptc = PTC_BOOLEAN
    name = "boolean"

    def __init__(self, pfc, bits):
        self.pfc = pfc
        self.bits = bits
        if bits == 8:
            self.fmt = "B"

    def check(self, value):
        if value is True or value is False or value == 0 or value == 1:
            return 1 if value else 0
        self.fail(value, "a boolean")

    def write(self, enc, value):
        if value is True or value is False or value == 0 or value == 1:
            enc.write(1 if value else 0, self.bits)
        else:
            self.fail(value, "a boolean")

    def read(self, dec):
        return dec.read(self.bits) != 0


class Unsigned(FieldType):
    """PTC 2 (enumerated) and PTC 3 (unsigned integer): ``bits`` wide, MSB first."""

    name = "unsigned"

    def __init__(self, ptc, pfc, bits):
        self.ptc = ptc
        self.pfc = pfc
        self.bits = bits
        self.max = (1 << bits) - 1
        self.fmt = _INT_FMT.get(bits)
        self.name = ("enumerated%d" if ptc == PTC_ENUMERATED else "uint%d") % bits

    def check(self, value):
        try:
            ok = 0 <= value <= self.max and value == int(value)
        except (TypeError, ValueError, OverflowError):
            ok = False
        if not ok or isinstance(value, float):
            self.fail(value, "an integer in 0..%d" % self.max)
        return value

    def write(self, enc, value):
        try:
            enc.write(value, self.bits)
        except (BitsValueError, TypeError, AttributeError):
            self.fail(value, "an integer in 0..%d" % self.max)

    def read(self, dec):
        return dec.read(self.bits)


class Signed(FieldType):
    """PTC 4: two's complement integer ``bits`` wide."""

    ptc = PTC_SIGNED

    def __init__(self, pfc, bits):
        self.pfc = pfc
        self.bits = bits
        self.min = -(1 << (bits - 1))
        self.max = (1 << (bits - 1)) - 1
        self._mask = (1 << bits) - 1
        self.fmt = _INT_FMT.get(bits)
        if self.fmt:
            self.fmt = self.fmt.lower()
        self.name = "int%d" % bits

    def check(self, value):
        try:
            ok = self.min <= value <= self.max and value == int(value)
        except (TypeError, ValueError, OverflowError):
            ok = False
        if not ok or isinstance(value, float):
            self.fail(value, "an integer in %d..%d" % (self.min, self.max))
        return value

    def write(self, enc, value):
        self.check(value)
        enc.write(value & self._mask, self.bits)

    def read(self, dec):
        v = dec.read(self.bits)
        return v - (1 << self.bits) if v > self.max else v


class Real(FieldType):
    """PTC 5: IEEE 754 single (PFC 1) or double (PFC 2) precision."""

    ptc = PTC_REAL

    def __init__(self, pfc):
        self.pfc = pfc
        self.bits = 32 if pfc == REAL_IEEE_SINGLE else 64
        self.fmt = "f" if pfc == REAL_IEEE_SINGLE else "d"
        self._sfmt = ">" + self.fmt
        self.name = "float32" if pfc == REAL_IEEE_SINGLE else "float64"

    def check(self, value):
        try:
            v = float(value)
        except (TypeError, ValueError):
            self.fail(value, "a real number")
        if self.pfc == REAL_IEEE_SINGLE and _FLT_MAX < abs(v) < _INF:
            self.fail(value, "a real number within IEEE single range")
        return v

    def write(self, enc, value):
        enc.write_struct(self._sfmt, self.check(value))

    def read(self, dec):
        return dec.read_struct(self._sfmt, self.bits >> 3)[0]


class MilStd1750(FieldType):
    """PTC 5 PFC 3/4: MIL-STD-1750A floating point, 32-bit simple and 48-bit extended.

    Simple: 24-bit two's complement mantissa then 8-bit two's complement exponent.
    Extended: 24-bit mantissa (most significant part), 8-bit exponent, then the 16 least
    significant mantissa bits. value = mantissa (a fraction in [-1, 1)) * 2**exponent.
    """

    ptc = PTC_REAL

    def __init__(self, pfc):
        self.pfc = pfc
        self.extended = pfc == REAL_MIL_EXTENDED
        self.bits = 48 if self.extended else 32
        self._mbits = 40 if self.extended else 24
        self.name = "mil1750a_%s" % ("extended" if self.extended else "simple")

    def encode(self, value):
        """(mantissa, exponent) as signed integers, normalised as the standard requires."""
        try:
            v = float(value)
        except (TypeError, ValueError):
            self.fail(value, "a real number")
        if v != v or v in (_INF, -_INF):
            self.fail(value, "a finite real number")
        if v == 0:
            return 0, 0
        m, e = math.frexp(v)  # 0.5 <= |m| < 1
        top = 1 << (self._mbits - 1)
        mi = int(math.floor(m * top + 0.5))
        if mi == top:  # rounded up to 1.0
            mi >>= 1
            e += 1
        elif mi == -(top >> 1):  # -0.5 is not normalised; -1.0 * 2**(e-1) is
            mi = -top
            e -= 1
        if e > 127:
            self.fail(value, "a real number within MIL-STD-1750A range")
        if e < -128:
            return 0, 0  # below the smallest normalised value: flush to zero
        return mi, e

    def check(self, value):
        self.encode(value)
        return value

    def write(self, enc, value):
        mi, e = self.encode(value)
        m = mi & ((1 << self._mbits) - 1)
        if self.extended:
            enc.write(((m >> 16) << 24) | ((e & 0xFF) << 16) | (m & 0xFFFF), 48)
        else:
            enc.write((m << 8) | (e & 0xFF), 32)

    def read(self, dec):
        raw = dec.read(self.bits)
        if self.extended:
            m = ((raw >> 24) << 16) | (raw & 0xFFFF)
            e = (raw >> 16) & 0xFF
        else:
            m = raw >> 8
            e = raw & 0xFF
        if m >> (self._mbits - 1):
            m -= 1 << self._mbits
        if e > 127:
            e -= 256
        return math.ldexp(m, e - self._mbits + 1)


_CACHE = {}


def field(ptc, pfc, **mission):
    """The field type for ``(ptc, pfc)``; ``mission`` holds the mission-defined parameters.

    Variable-length strings (PTC 6-8 PFC 0) take ``length_bits`` (size of the length prefix,
    default 16) and ``max_length``; times (PTC 9, 10) take ``epoch`` and, for PFC 0,
    ``default_code``; packets (PTC 12) take ``codec``; deduced fields (PTC 11) take ``key``
    and ``lookup``.
    """
    if isinstance(ptc, bool) or isinstance(pfc, bool):
        raise FieldTypeError(ptc, pfc, "codes are integers")
    if not mission:
        ft = _CACHE.get((ptc, pfc))
        if ft is not None:
            return ft
    ft = _make(ptc, pfc, mission)
    if not mission:
        _CACHE[(ptc, pfc)] = ft
    return ft


def _make(ptc, pfc, mission):
    if ptc in (PTC_BIT_STRING, PTC_OCTET_STRING, PTC_CHARACTER_STRING, PTC_PACKET):
        from obsw.pus import ptc_strings

        return ptc_strings.make(ptc, pfc, mission)
    if ptc in (PTC_ABSOLUTE_TIME, PTC_RELATIVE_TIME):
        from obsw.pus import ptc_time

        return ptc_time.make(ptc, pfc, mission)
    if ptc == PTC_DEDUCED:
        from obsw.pus import structure

        return structure.make_deduced(pfc, mission)
    if mission:
        raise FieldTypeError(ptc, pfc, "takes no mission parameters: %s" % sorted(mission))
    if ptc == PTC_BOOLEAN:
        # PFC 0: one bit (ECSS-E-70-41A, SCOS-2000); PFC 1: one bit; PFC 8: one octet.
        if pfc in (0, 1):
            return Boolean(pfc, 1)
        if pfc == 8:
            return Boolean(pfc, 8)
    elif ptc == PTC_ENUMERATED:
        if pfc in ENUMERATED_PFCS:
            return Unsigned(ptc, pfc, pfc)
    elif ptc == PTC_UNSIGNED:
        if 0 <= pfc < len(INTEGER_BITS):
            return Unsigned(ptc, pfc, INTEGER_BITS[pfc])
    elif ptc == PTC_SIGNED:
        if 0 <= pfc <= _SIGNED_PFC_MAX:
            return Signed(pfc, INTEGER_BITS[pfc])
    elif ptc == PTC_REAL:
        if pfc in (REAL_IEEE_SINGLE, REAL_IEEE_DOUBLE):
            return Real(pfc)
        if pfc in (REAL_MIL_SIMPLE, REAL_MIL_EXTENDED):
            return MilStd1750(pfc)
    else:
        raise FieldTypeError(ptc, pfc, "PTC must be 1..12")
    raise FieldTypeError(ptc, pfc)


def uint_pfc(bits):
    """The PTC 3 PFC for an unsigned integer ``bits`` wide."""
    if bits in INTEGER_BITS:
        return INTEGER_BITS.index(bits)
    raise FieldTypeError(PTC_UNSIGNED, None, "no unsigned integer of %r bits" % bits)


def int_pfc(bits):
    """The PTC 4 PFC for a signed integer ``bits`` wide."""
    pfc = INTEGER_BITS.index(bits) if bits in INTEGER_BITS else -1
    if 0 <= pfc <= _SIGNED_PFC_MAX:
        return pfc
    raise FieldTypeError(PTC_SIGNED, None, "no signed integer of %r bits" % bits)
