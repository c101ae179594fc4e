"""Message layouts of ST[12] on-board monitoring: definitions whose fields depend on the
check type, limits typed by the monitored parameter.

A parameter monitoring definition (PMON) is a head (ID, monitored parameter, validity
parameter with mask and expected value, monitoring interval, repetition number, check
type) and the check type's own fields: an expected-value check has a mask, an expected
value and an event; a limit check a low limit and its event and a high limit and its event
(limits of the parameter's own type); a delta check low and high thresholds on the mean of
a number of consecutive deltas (float64) with their events. Event ID 0 raises no event.
A check transition of an expected-value check carries the check's mask before the value.

A functional monitoring definition (FMON) is an ID, a validity condition (parameter, mask,
expected value), the event it raises when it fails, the minimum number of failing PMONs that
fails it, and its PMON IDs; reports add its protection and enabled statuses.
"""

from obsw.bits import Decoder, Encoder
from obsw.compat import const
from obsw.pus.fields import FieldValueError, field
from obsw.pus.ptc_time import cuc_pfc
from obsw.pus.services.base import E8, EVENT_ID, PARAMETER_ID, U16, U32
from obsw.pus.structure import Repeated, Structure

# mission field sizes of service 12
PMON_ID = U16
PMON_COUNT = U16
CHECK_TYPE = E8
CHECKING_STATUS = E8
STATUS = E8  # 1 enabled, 0 disabled
INTERVAL = U16  # in minimum sampling intervals (application process cycles)
REPETITIONS = U16
DELAY = U16  # maximum transition reporting delay, in cycles
MASK = U32
DELTA = field(5, 2)
TRANSITION_TIME = field(9, cuc_pfc(4, 2))

# check types
CHECK_EXPECTED_VALUE = const(0)
CHECK_LIMIT = const(1)
CHECK_DELTA = const(2)

# checking statuses
UNCHECKED = const(0)
INVALID = const(1)
WITHIN = const(2)  # within limits or thresholds; the expected value
BELOW_LOW = const(3)  # below the low limit or threshold; an unexpected value
ABOVE_HIGH = const(4)  # above the high limit or threshold

CHECK_NAMES = {CHECK_EXPECTED_VALUE: "expected value", CHECK_LIMIT: "limit", CHECK_DELTA: "delta"}
STATUS_NAMES = {
    UNCHECKED: "unchecked",
    INVALID: "invalid",
    WITHIN: "within",
    BELOW_LOW: "below low",
    ABOVE_HIGH: "above high",
}

_HEAD = [
    ("pmon", PMON_ID),
    ("parameter", PARAMETER_ID),
    ("validity", PARAMETER_ID),
    ("validity_mask", MASK),
    ("validity_value", MASK),
    ("interval", INTERVAL),
]
EMPTY = Structure([])
IDS = Structure([("ids", Repeated(PMON_COUNT, PMON_ID))])
DELAY_LAYOUT = Structure([("delay", DELAY)])
STATUS_REPORT = Structure(
    [("items", Repeated(PMON_COUNT, [("pmon", PMON_ID), ("enabled", STATUS)]))]
)


# functional monitoring (FMON): field sizes, statuses, messages
FMON_ID = U16
FMON_COUNT = U16
FAILING_NUMBER = U16  # minimum number of failing PMONs that fails the FMON
PROTECTION = E8  # 1 protected, 0 unprotected
FMON_CHECKING_STATUS = E8
FMON_UNCHECKED = const(0)
FMON_RUNNING = const(1)
FMON_INVALID = const(2)
FMON_FAILED = const(3)
FMON_STATUS_NAMES = {
    FMON_UNCHECKED: "unchecked",
    FMON_RUNNING: "running",
    FMON_INVALID: "invalid",
    FMON_FAILED: "failed",
}


class FmonLayouts:
    """The functional monitoring messages: ``ids`` (TC[12,19]-[12,22], [12,24], [12,25]),
    ``add`` (TC[12,23]), ``report`` (TM[12,26]), ``status`` (TM[12,28]). Built on first use
    by ``fmon_layouts()``: a board that defines no FMON keeps their heap."""

    def __init__(self):
        validity = [
            ("validity", PARAMETER_ID),
            ("validity_mask", MASK),
            ("validity_value", MASK),
        ]
        pmons = ("pmons", Repeated(FMON_COUNT, PMON_ID))
        self.ids = Structure([("ids", Repeated(FMON_COUNT, FMON_ID))])
        tail = [("event", EVENT_ID), ("failing", FAILING_NUMBER), pmons]
        head = [("fmon", FMON_ID)] + validity
        self.add = Structure([("items", Repeated(FMON_COUNT, head + tail))])
        flags = [("protected", PROTECTION), ("enabled", STATUS)]
        self.report = Structure([("items", Repeated(FMON_COUNT, head + flags + tail))])
        status = [("fmon", FMON_ID)] + flags + [("checking", FMON_CHECKING_STATUS)]
        self.status = Structure([("items", Repeated(FMON_COUNT, status))])


_fmon_layouts = []


def fmon_layouts():
    """The one ``FmonLayouts``, built on the first call."""
    if not _fmon_layouts:
        _fmon_layouts.append(FmonLayouts())
    return _fmon_layouts[0]


class Items:
    """An optional prefix, then N items: a head and the fields its check type selects."""

    def __init__(self, prefix, head, variants):
        self.prefix = prefix
        self.head = head
        self.variants = variants

    def _variant(self, check):
        v = self.variants.get(check)
        if v is None:
            raise FieldValueError("check type", check, "one of %s" % sorted(self.variants))
        return v

    def pack(self, values):
        enc = Encoder()
        if self.prefix is not None:
            self.prefix.write(enc, values)
        items = values["items"]
        PMON_COUNT.write(enc, len(items))
        for it in items:
            self.head.write(enc, it)
            self._variant(it["check"]).write(enc, it, [it])
        return enc.getvalue()

    def unpack(self, data):
        dec = Decoder(data)
        out = self.prefix.read(dec) if self.prefix is not None else {}
        items = []
        for _ in range(PMON_COUNT.read(dec)):
            it = self.head.read(dec)
            it.update(self._variant(it["check"]).read(dec, [it]))
            items.append(it)
        if dec.bits_left >= 8:
            raise FieldValueError("structure", dec.bits_left >> 3, "no trailing octets")
        out["items"] = items
        return out


class Layouts:
    """The service 12 messages; ``types(pid)`` gives a parameter's field type."""

    def __init__(self, types):
        value = field(11, 0, key="parameter", lookup=types)
        specs = {
            CHECK_EXPECTED_VALUE: Structure(
                [("mask", MASK), ("expected", MASK), ("event", EVENT_ID)]
            ),
            CHECK_LIMIT: Structure(
                [
                    ("low", value),
                    ("low_event", EVENT_ID),
                    ("high", value),
                    ("high_event", EVENT_ID),
                ]
            ),
            CHECK_DELTA: Structure(
                [
                    ("low", DELTA),
                    ("low_event", EVENT_ID),
                    ("high", DELTA),
                    ("high_event", EVENT_ID),
                    ("consecutive", REPETITIONS),
                ]
            ),
        }
        check = [("repetitions", REPETITIONS), ("check", CHECK_TYPE)]
        self.add = Items(None, Structure(_HEAD + check), specs)
        self.modify = Items(
            None, Structure([("pmon", PMON_ID), ("parameter", PARAMETER_ID)] + check), specs
        )
        self.report = Items(DELAY_LAYOUT, Structure(_HEAD + [("enabled", STATUS)] + check), specs)
        tail = [
            ("previous", CHECKING_STATUS),
            ("current", CHECKING_STATUS),
            ("time", TRANSITION_TIME),
        ]
        entries = {
            CHECK_EXPECTED_VALUE: Structure(
                [("mask", MASK), ("value", value), ("limit", MASK)] + tail
            ),
            CHECK_LIMIT: Structure([("value", value), ("limit", value)] + tail),
            CHECK_DELTA: Structure([("value", DELTA), ("limit", DELTA)] + tail),
        }
        self.transitions = Items(
            None,
            Structure([("pmon", PMON_ID), ("parameter", PARAMETER_ID), ("check", CHECK_TYPE)]),
            entries,
        )
