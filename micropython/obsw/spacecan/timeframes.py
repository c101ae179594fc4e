"""SpaceCAN broadcast frames: heartbeat, sync, SCET time (0x180) and UTC time (0x200)."""

import struct

from obsw.compat import const
from obsw.errors import wrong_length

_SCET_LEN = const(7)
_UTC_LEN = const(8)


class CanFrameLengthError(ValueError):
    """A CAN frame whose data length does not match its identifier's format (``obsw.errors``:
    the length kind)."""

    def __init__(self, what, expected, got):
        super().__init__(wrong_length("%s frame data" % what, expected, got))
        self.what = what
        self.expected = expected
        self.got = got


class FieldRangeError(ValueError):
    """A field value that does not fit its wire width."""

    def __init__(self, field, value, bits):
        super().__init__("%s must fit %d bits unsigned, got %r" % (field, bits, value))
        self.field = field
        self.value = value


def _check(field, value, bits):
    if not isinstance(value, int) or value < 0 or value >> bits:
        raise FieldRangeError(field, value, bits)
    return value


class ScetTime:
    """Spacecraft elapsed time: fine_time u24 then coarse_time u32, both big-endian."""

    def __init__(self, coarse_time, fine_time=0):
        self.coarse_time = _check("coarse_time", coarse_time, 32)
        self.fine_time = _check("fine_time", fine_time, 24)

    def pack(self):
        return struct.pack(">BHI", self.fine_time >> 16, self.fine_time & 0xFFFF, self.coarse_time)

    @classmethod
    def unpack(cls, buf):
        if len(buf) != _SCET_LEN:
            raise CanFrameLengthError("SCET", _SCET_LEN, len(buf))
        hi, lo, coarse = struct.unpack(">BHI", buf)
        return cls(coarse, (hi << 16) | lo)

    def seconds(self):
        """Coarse seconds plus the fine part as a fraction of 2**24."""
        return self.coarse_time + self.fine_time / 16777216

    def __eq__(self, other):
        return (
            isinstance(other, ScetTime)
            and other.coarse_time == self.coarse_time
            and other.fine_time == self.fine_time
        )

    def __repr__(self):
        return "ScetTime(coarse_time=%d, fine_time=%d)" % (self.coarse_time, self.fine_time)


class UtcTime:
    """UTC: sub_ms u16, ms_of_day u32, day u16, each big-endian, in that order on the wire."""

    def __init__(self, day, ms_of_day, sub_ms=0):
        self.day = _check("day", day, 16)
        self.ms_of_day = _check("ms_of_day", ms_of_day, 32)
        self.sub_ms = _check("sub_ms", sub_ms, 16)

    def pack(self):
        return struct.pack(">HIH", self.sub_ms, self.ms_of_day, self.day)

    @classmethod
    def unpack(cls, buf):
        if len(buf) != _UTC_LEN:
            raise CanFrameLengthError("UTC", _UTC_LEN, len(buf))
        sub_ms, ms, day = struct.unpack(">HIH", buf)
        return cls(day, ms, sub_ms)

    def __eq__(self, other):
        return (
            isinstance(other, UtcTime)
            and other.day == self.day
            and other.ms_of_day == self.ms_of_day
            and other.sub_ms == self.sub_ms
        )

    def __repr__(self):
        return "UtcTime(day=%d, ms_of_day=%d, sub_ms=%d)" % (self.day, self.ms_of_day, self.sub_ms)


def check_empty(what, data):
    """Heartbeat and sync frames carry no data."""
    if len(data):
        raise CanFrameLengthError(what, 0, len(data))
