"""PTC 9 absolute time and PTC 10 relative time field types (CCSDS CUC and CDS codes).

PFC table (the same CUC numbering for both types):
- PTC 9 PFC 0: explicit, a P-field then its T-field (any CUC or CDS format);
- PTC 9 PFC 1: CDS, 16-bit day, 32-bit ms of day; PFC 2: the same plus 16-bit microseconds;
- PFC 3..18: CUC with c = (PFC + 1) // 4 coarse octets (1..4), f = (PFC + 1) % 4 fine (0..3);
- PFC 19..46: CUC with c = (PFC - 19) // 7 + 1 coarse octets, f = (PFC - 19) % 7 + 4 fine.
Values are integer components, exact on every float width: (coarse, fine) for CUC,
(day, ms, sub-ms) for CDS, (time code, components) for PFC 0. Writers also take seconds
(int or float) since the epoch. Relative times are CUC in two's complement: (coarse, fine)
with a negative coarse for negative durations (seconds = coarse + fine / 2**(8 * f)).
"""

from obsw.bits import BitsTooShortError
from obsw.pus.fields import (
    PTC_ABSOLUTE_TIME,
    PTC_RELATIVE_TIME,
    FieldType,
    FieldTypeError,
)
from obsw.timecode import Cds, Cuc, TimeCodeError, from_pfield

CUC_PFC_FIRST = 3
CUC_PFC_LAST = 46


def cuc_octets(pfc):
    """(coarse octets, fine octets) for a CUC PFC 3..46."""
    if 3 <= pfc <= 18:
        return (pfc + 1) >> 2, (pfc + 1) & 3
    if 19 <= pfc <= 46:
        return (pfc - 19) // 7 + 1, (pfc - 19) % 7 + 4
    raise FieldTypeError(PTC_ABSOLUTE_TIME, pfc, "not a CUC format code")


def cuc_pfc(coarse, fine):
    """The PFC of the CUC format with ``coarse`` (1..4) and ``fine`` (0..10) octets."""
    if 1 <= coarse <= 4 and 0 <= fine <= 3:
        return coarse * 4 + fine - 1
    if 1 <= coarse <= 4 and 4 <= fine <= 10:
        return 19 + (coarse - 1) * 7 + fine - 4
    raise FieldTypeError(PTC_ABSOLUTE_TIME, None, "no CUC PFC for %r+%r octets" % (coarse, fine))


def make(ptc, pfc, mission):
    mission = dict(mission)
    epoch = mission.pop("epoch", None)
    default_code = mission.pop("default_code", None)
    if mission:
        raise FieldTypeError(ptc, pfc, "unknown parameters %s" % sorted(mission))
    if not isinstance(pfc, int):
        raise FieldTypeError(ptc, pfc)
    if ptc == PTC_ABSOLUTE_TIME:
        if pfc == 0:
            return ExplicitTime(default_code, epoch)
        if pfc in (1, 2):
            return AbsoluteTime(pfc, Cds(2, 2 * (pfc - 1), epoch))
        if CUC_PFC_FIRST <= pfc <= CUC_PFC_LAST:
            return AbsoluteTime(pfc, Cuc(*cuc_octets(pfc), epoch=epoch))
    elif CUC_PFC_FIRST <= pfc <= CUC_PFC_LAST:
        return RelativeTime(pfc, Cuc(*cuc_octets(pfc)))
    raise FieldTypeError(ptc, pfc)


def _components(ft, code, value):
    """Integer components for ``code`` from a tuple or from seconds."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return code.from_seconds(value)
    sizes = (2,) if isinstance(code, Cuc) else (2, 3)  # CDS: (day, ms) or (day, ms, sub)
    if isinstance(value, (tuple, list)) and len(value) in sizes:
        return tuple(value)
    ft.fail(value, "seconds or a tuple of %d time components" % sizes[-1])


class AbsoluteTime(FieldType):
    """PTC 9 with an implicit format (PFC 1..46): only the T-field is on the wire."""

    ptc = PTC_ABSOLUTE_TIME

    def __init__(self, pfc, code):
        self.pfc = pfc
        self.code = code
        self.bits = code.tsize * 8
        self.name = "absolute time %r" % (code,)

    def check(self, value):
        comps = _components(self, self.code, value)
        try:
            self.code.pack(*comps)
        except TimeCodeError as e:
            self.fail(value, str(e))
        except TypeError:
            self.fail(value, "integer time components")
        return comps

    def write(self, enc, value):
        comps = _components(self, self.code, value)
        try:
            enc.write_bytes(self.code.pack(*comps))
        except TimeCodeError as e:
            self.fail(value, str(e))
        except TypeError:
            self.fail(value, "integer time components")

    def read(self, dec):
        return self.code.unpack(dec.read_bytes(self.code.tsize))

    def seconds(self, value):
        """Seconds since the epoch for a value this field read."""
        return self.code.to_seconds(*value)


class ExplicitTime(FieldType):
    """PTC 9 PFC 0: the P-field travels with the time; the value is (time code, components).

    ``default_code`` (a Cuc or Cds) is used when the writer passes components or seconds only.
    """

    ptc = PTC_ABSOLUTE_TIME
    pfc = 0
    bits = None
    name = "absolute time, explicit P-field"

    def __init__(self, default_code=None, agency_epoch=None):
        self.default_code = default_code
        self.agency_epoch = agency_epoch  # for P-fields that say 'agency-defined epoch'

    def _split(self, value):
        if (
            isinstance(value, (tuple, list))
            and len(value) == 2
            and isinstance(value[0], (Cuc, Cds))
        ):
            return value[0], value[1]
        if self.default_code is None:
            self.fail(value, "(time code, components)")
        return self.default_code, value

    def check(self, value):
        code, comps = self._split(value)
        comps = _components(self, code, comps)
        try:
            code.pack(*comps)
        except (TimeCodeError, TypeError) as e:
            self.fail(value, str(e))
        return code, comps

    def write(self, enc, value):
        code, comps = self.check(value)
        enc.write_bytes(code.pfield())
        enc.write_bytes(code.pack(*comps)[-code.tsize :])

    def read(self, dec):
        start = dec.bit_position
        p1 = dec.read_bytes(1)
        psize = 2 if p1[0] & 0x80 else 1
        dec.pos = start
        pfield = dec.read_bytes(psize)
        try:
            code, _ = from_pfield(pfield, 0, self.agency_epoch or 0)
        except TimeCodeError:
            dec.pos = start
            raise
        if dec.bits_left < code.tsize * 8:
            left = dec.bits_left
            dec.pos = start
            raise BitsTooShortError("buffer", code.tsize * 8, left)
        comps = code.unpack(pfield + dec.read_bytes(code.tsize))
        return code, comps


class RelativeTime(FieldType):
    """PTC 10 (PFC 3..46): a signed CUC duration, two's complement over the whole T-field."""

    ptc = PTC_RELATIVE_TIME

    def __init__(self, pfc, code):
        self.pfc = pfc
        self.code = code
        self.bits = code.tsize * 8
        self._fbits = code.fine * 8
        self._half = 1 << (self.bits - 1)
        self.name = "relative time %r" % (code,)

    def _ticks(self, value):
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            c, f = self.code.from_seconds(value)
        elif isinstance(value, (tuple, list)) and len(value) == 2:
            c, f = value
        else:
            self.fail(value, "seconds or (coarse, fine)")
        if not isinstance(c, int) or not isinstance(f, int) or not 0 <= f < self.code.fine_ticks:
            self.fail(value, "integer coarse and fine in 0..%d" % (self.code.fine_ticks - 1))
        t = (c << self._fbits) | f
        if not -self._half <= t < self._half:
            self.fail(value, "a duration within %d signed bits" % self.bits)
        return t

    def check(self, value):
        self._ticks(value)
        return value

    def write(self, enc, value):
        enc.write(self._ticks(value) & ((self._half << 1) - 1), self.bits)

    def read(self, dec):
        t = dec.read(self.bits)
        if t >= self._half:
            t -= self._half << 1
        return t >> self._fbits, t & (self.code.fine_ticks - 1)

    def seconds(self, value):
        return self.code.to_seconds(*value)
