"""CCSDS 301.0-B-4 time codes: CUC (unsegmented) and CDS (day segmented), P-field and T-field."""

import struct

from obsw.compat import const
from obsw.errors import too_short

# Time code identification (P-field bits 1-3).
CODE_CUC_1958 = const(0b001)  # CUC, level 1: epoch 1958-01-01 TAI
CODE_CUC_AGENCY = const(0b010)  # CUC, level 2: agency-defined epoch
CODE_CDS = const(0b100)
CODE_CCS = const(0b101)

_MS_PER_DAY = const(86400000)
_MS_MAX = const(86400999)  # a day with a positive leap second ends at 86 400 999 ms


class TimeCodeError(ValueError):
    """Base of the time code errors."""


class TimeCodeTooShortError(TimeCodeError):
    """Fewer bytes than a time code or its P-field needs (``obsw.errors``: the too-short kind)."""

    def __init__(self, what, needed, got):
        super().__init__(too_short(what, needed, got))
        self.what = what
        self.needed = needed
        self.got = got


class PFieldMismatchError(TimeCodeError):
    """An explicit P-field that differs from the one this code expects."""

    def __init__(self, expected, got):
        super().__init__("P-field mismatch: expected %s, got %s" % (_hex(expected), _hex(got)))
        self.expected = expected
        self.got = got


class TimeCodeFormatError(TimeCodeError):
    """A time code configuration or P-field the standard does not define (or we do not)."""

    def __init__(self, msg, value=None):
        super().__init__(msg)
        self.value = value


class TimeValueError(TimeCodeError):
    """A time component outside what its field can carry."""

    def __init__(self, what, value, maximum, minimum=0):
        super().__init__("%s %r out of range %d..%d" % (what, value, minimum, maximum))
        self.what = what
        self.value = value
        self.minimum = minimum
        self.maximum = maximum


def _hex(b):
    return "".join("%02x" % x for x in b)


def _check_pfield(buf, offset, pfield):
    n = len(pfield)
    if len(buf) - offset < n:
        raise TimeCodeTooShortError("P-field", n, max(len(buf) - offset, 0))
    got = bytes(buf[offset : offset + n])
    if got != pfield:
        raise PFieldMismatchError(pfield, got)


class Cuc:
    """CCSDS unsegmented time code: ``coarse`` octets of seconds, ``fine`` octets of fraction.

    ``epoch`` None is the CCSDS epoch 1958-01-01 TAI (code 001); an int is an agency-defined
    epoch (code 010), given as its offset in seconds from 1958-01-01 TAI.
    ``explicit`` puts the P-field in front of every T-field.
    """

    def __init__(self, coarse=4, fine=2, epoch=None, explicit=False):
        if not 1 <= coarse <= 7:
            raise TimeCodeFormatError("CUC coarse time must be 1..7 octets, got %r" % coarse)
        if not 0 <= fine <= 10:
            raise TimeCodeFormatError("CUC fine time must be 0..10 octets, got %r" % fine)
        self.coarse = coarse
        self.fine = fine
        self.epoch = epoch
        self.explicit = explicit
        self.code = CODE_CUC_1958 if epoch is None else CODE_CUC_AGENCY
        self.epoch_offset = 0 if epoch is None else epoch
        self.tsize = coarse + fine
        ext = coarse > 4 or fine > 3
        p1 = (ext << 7) | (self.code << 4) | ((min(coarse, 4) - 1) << 2) | min(fine, 3)
        if ext:
            self._pfield = bytes((p1, (max(coarse - 4, 0) << 5) | (max(fine - 3, 0) << 2)))
        else:
            self._pfield = bytes((p1,))
        self.size = self.tsize + (len(self._pfield) if explicit else 0)
        self.fine_ticks = 1 << (8 * fine)  # fine counts per second
        self._fmt = {
            (4, 0): ">I",
            (4, 1): ">IB",
            (4, 2): ">IH",
            (4, 4): ">II",
            (2, 0): ">H",
            (1, 0): ">B",
        }.get((coarse, fine))

    def __eq__(self, other):
        return (
            isinstance(other, Cuc)
            and self.coarse == other.coarse
            and self.fine == other.fine
            and self.epoch == other.epoch
            and self.explicit == other.explicit
        )

    def __repr__(self):
        return "Cuc(coarse=%d, fine=%d, epoch=%r, explicit=%r)" % (
            self.coarse,
            self.fine,
            self.epoch,
            self.explicit,
        )

    def pfield(self):
        return self._pfield

    def pack(self, coarse, fine=0):
        """T-field (after the P-field when explicit) for whole seconds and fine ticks."""
        if not 0 <= coarse < (1 << (8 * self.coarse)):
            raise TimeValueError("CUC coarse time", coarse, (1 << (8 * self.coarse)) - 1)
        if not 0 <= fine < self.fine_ticks:
            raise TimeValueError("CUC fine time", fine, self.fine_ticks - 1)
        if self._fmt is not None:
            if self.fine:
                t = struct.pack(self._fmt, coarse, fine)
            else:
                t = struct.pack(self._fmt, coarse)
        else:
            t = ((coarse << (8 * self.fine)) | fine).to_bytes(self.tsize, "big")
        return self._pfield + t if self.explicit else t

    def unpack(self, buf, offset=0):
        """(coarse, fine) from ``buf`` at ``offset``; checks length and the P-field."""
        if len(buf) - offset < self.size:
            raise TimeCodeTooShortError("CUC time", self.size, max(len(buf) - offset, 0))
        if self.explicit:
            _check_pfield(buf, offset, self._pfield)
            offset += len(self._pfield)
        if self._fmt is not None:
            v = struct.unpack_from(self._fmt, buf, offset)
            return (v[0], v[1]) if self.fine else (v[0], 0)
        t = int.from_bytes(bytes(buf[offset : offset + self.tsize]), "big")
        return t >> (8 * self.fine), t & (self.fine_ticks - 1)

    def from_seconds(self, seconds):
        """(coarse, fine) nearest to ``seconds`` since this code's epoch (int or float)."""
        if isinstance(seconds, int):
            return seconds, 0
        whole = int(seconds // 1)
        fine = int((seconds - whole) * self.fine_ticks + 0.5)
        if fine >= self.fine_ticks:
            whole += 1
            fine -= self.fine_ticks
        return whole, fine

    def to_seconds(self, coarse, fine=0):
        return coarse + fine / self.fine_ticks if self.fine else coarse

    def pack_seconds(self, seconds):
        c, f = self.from_seconds(seconds)
        return self.pack(c, f)

    def unpack_seconds(self, buf, offset=0):
        c, f = self.unpack(buf, offset)
        return self.to_seconds(c, f)

    @classmethod
    def from_pfield(cls, buf, offset=0, agency_epoch=0):
        """(Cuc, P-field size) described by the P-field at ``offset``; explicit=True.

        An agency-defined epoch (code 010) is not carried in the P-field: ``agency_epoch``
        (seconds from 1958-01-01 TAI) supplies it.
        """
        if len(buf) - offset < 1:
            raise TimeCodeTooShortError("CUC P-field", 1, 0)
        p1 = buf[offset]
        code = (p1 >> 4) & 7
        if code not in (CODE_CUC_1958, CODE_CUC_AGENCY):
            raise TimeCodeFormatError("P-field time code id %d is not CUC" % code, code)
        coarse = ((p1 >> 2) & 3) + 1
        fine = p1 & 3
        size = 1
        if p1 & 0x80:
            if len(buf) - offset < 2:
                raise TimeCodeTooShortError("CUC P-field", 2, 1)
            p2 = buf[offset + 1]
            if p2 & 0x80:
                raise TimeCodeFormatError("CUC P-field: third octet is not defined", p2)
            coarse += (p2 >> 5) & 3
            fine += (p2 >> 2) & 7
            size = 2
        code_epoch = None if code == CODE_CUC_1958 else agency_epoch
        tc = cls(coarse, fine, code_epoch, True)
        if size == 2 and len(tc._pfield) == 1:
            # An extension octet that adds nothing: keep the P-field as it came.
            tc._pfield = bytes(buf[offset : offset + 2])
            tc.size = tc.tsize + 2
        else:
            # Bits 6-7 of the extension octet are mission-defined: carry them through.
            tc._pfield = bytes(buf[offset : offset + size])
        return tc, size


class Cds:
    """CCSDS day segmented time code: day count, milliseconds of day, optional sub-ms.

    ``day_octets`` 2 or 3; ``submilli_octets`` 0 (none), 2 (microseconds of millisecond) or
    4 (picoseconds of millisecond). ``epoch`` None is 1958-01-01; an int is an agency epoch
    (seconds from 1958-01-01, a multiple of a day).
    """

    def __init__(self, day_octets=2, submilli_octets=0, epoch=None, explicit=False):
        if day_octets not in (2, 3):
            raise TimeCodeFormatError("CDS day segment must be 2 or 3 octets", day_octets)
        if submilli_octets not in (0, 2, 4):
            raise TimeCodeFormatError(
                "CDS sub-millisecond segment must be 0, 2 or 4 octets", submilli_octets
            )
        self.day_octets = day_octets
        self.submilli_octets = submilli_octets
        self.epoch = epoch
        self.explicit = explicit
        self.epoch_offset = 0 if epoch is None else epoch
        res = submilli_octets >> 1  # 0 none, 1 microseconds, 2 picoseconds
        self._pfield = bytes(
            ((CODE_CDS << 4) | ((epoch is not None) << 3) | ((day_octets == 3) << 2) | res,)
        )
        self.sub_per_ms = (1, 0, 1000, 0, 1000000000)[submilli_octets]
        self.tsize = day_octets + 4 + submilli_octets
        self.size = self.tsize + (1 if explicit else 0)
        self._fmt = (
            ">" + ("H" if day_octets == 2 else "") + "I" + ("", "", "H", "", "I")[submilli_octets]
        )

    def __eq__(self, other):
        return (
            isinstance(other, Cds)
            and self.day_octets == other.day_octets
            and self.submilli_octets == other.submilli_octets
            and self.epoch == other.epoch
            and self.explicit == other.explicit
        )

    def __repr__(self):
        return "Cds(day_octets=%d, submilli_octets=%d, epoch=%r, explicit=%r)" % (
            self.day_octets,
            self.submilli_octets,
            self.epoch,
            self.explicit,
        )

    def pfield(self):
        return self._pfield

    def _check(self, day, ms, sub):
        if not 0 <= day < (1 << (8 * self.day_octets)):
            raise TimeValueError("CDS day", day, (1 << (8 * self.day_octets)) - 1)
        if not 0 <= ms <= _MS_MAX:
            raise TimeValueError("CDS milliseconds of day", ms, _MS_MAX)
        if not 0 <= sub < self.sub_per_ms:
            raise TimeValueError("CDS sub-milliseconds", sub, self.sub_per_ms - 1)

    def pack(self, day, ms, sub=0):
        """T-field (after the P-field when explicit) for day, ms of day and sub-ms."""
        self._check(day, ms, sub)
        if self.day_octets == 2:
            if self.submilli_octets:
                t = struct.pack(self._fmt, day, ms, sub)
            else:
                t = struct.pack(self._fmt, day, ms)
        else:
            t = day.to_bytes(3, "big") + (
                struct.pack(self._fmt, ms, sub) if self.submilli_octets else struct.pack(">I", ms)
            )
        return self._pfield + t if self.explicit else t

    def unpack(self, buf, offset=0):
        """(day, ms, sub) from ``buf`` at ``offset``; checks length, P-field and ranges."""
        if len(buf) - offset < self.size:
            raise TimeCodeTooShortError("CDS time", self.size, max(len(buf) - offset, 0))
        if self.explicit:
            _check_pfield(buf, offset, self._pfield)
            offset += 1
        if self.day_octets == 2:
            v = struct.unpack_from(self._fmt, buf, offset)
        else:
            v = (int.from_bytes(bytes(buf[offset : offset + 3]), "big"),) + struct.unpack_from(
                self._fmt, buf, offset + 3
            )
        day, ms = v[0], v[1]
        sub = v[2] if self.submilli_octets else 0
        self._check(day, ms, sub)
        return day, ms, sub

    def from_seconds(self, seconds):
        """(day, ms, sub) for ``seconds`` since the epoch, counting 86 400 s per day."""
        if isinstance(seconds, int):
            return seconds // 86400, (seconds % 86400) * 1000, 0
        day = int(seconds // 86400)
        rest = seconds - day * 86400
        ticks = int(rest * 1000 * self.sub_per_ms + 0.5)
        ms, sub = divmod(ticks, self.sub_per_ms)
        if ms >= _MS_PER_DAY:
            day += 1
            ms -= _MS_PER_DAY
        return day, ms, sub

    def to_seconds(self, day, ms, sub=0):
        if sub:
            return day * 86400 + ms / 1000 + sub / (1000 * self.sub_per_ms)
        if ms % 1000:
            return day * 86400 + ms / 1000
        return day * 86400 + ms // 1000

    def pack_seconds(self, seconds):
        return self.pack(*self.from_seconds(seconds))

    def unpack_seconds(self, buf, offset=0):
        return self.to_seconds(*self.unpack(buf, offset))

    @classmethod
    def from_pfield(cls, buf, offset=0, agency_epoch=0):
        """(Cds, 1) described by the P-field at ``offset``; explicit=True."""
        if len(buf) - offset < 1:
            raise TimeCodeTooShortError("CDS P-field", 1, 0)
        p1 = buf[offset]
        code = (p1 >> 4) & 7
        if code != CODE_CDS or p1 & 0x80:
            raise TimeCodeFormatError("P-field 0x%02x is not a CDS P-field" % p1, p1)
        res = p1 & 3
        if res == 3:
            raise TimeCodeFormatError("CDS sub-millisecond resolution code 3 is reserved", p1)
        epoch = agency_epoch if p1 & 8 else None
        return cls(3 if p1 & 4 else 2, res * 2, epoch, True), 1


def from_pfield(buf, offset=0, agency_epoch=0):
    """(time code, P-field size) for any P-field this module knows (CUC or CDS)."""
    if len(buf) - offset < 1:
        raise TimeCodeTooShortError("P-field", 1, 0)
    code = (buf[offset] >> 4) & 7
    if code == CODE_CDS:
        return Cds.from_pfield(buf, offset, agency_epoch)
    if code in (CODE_CUC_1958, CODE_CUC_AGENCY):
        return Cuc.from_pfield(buf, offset, agency_epoch)
    raise TimeCodeFormatError("unsupported time code id %d in P-field" % code, code)
