"""Property tests of the functional monitoring and parameter definition messages (round trips,
junk raises only the declared decode errors) and of calibrations (raw -> engineering -> raw)."""

from hypothesis import assume, given, settings
from hypothesis import strategies as st
from obsw.bits import BitsTooShortError, BitsValueError
from obsw.pus.calibration import Values, calibration
from obsw.pus.fields import FieldValueError, field
from obsw.pus.services.s12_layouts import fmon_layouts
from obsw.pus.services.s20_parameters import (
    DEFINITION_REPORT,
    OBJECT_DEFINITIONS,
    RAW_DEFINITIONS,
)

DECODE_ERRORS = (BitsTooShortError, BitsValueError, FieldValueError)
SETTINGS = settings(max_examples=200, deadline=None)
U16 = st.integers(0, 0xFFFF)
U32 = st.integers(0, 0xFFFFFFFF)
FLAG = st.integers(0, 1)


def _fmon(report):
    fields = {
        "fmon": U16,
        "validity": U16,
        "validity_mask": U32,
        "validity_value": U32,
        "event": U16,
        "failing": U16,
        "pmons": st.lists(U16, max_size=8),
    }
    if report:
        fields.update(protected=FLAG, enabled=FLAG)
    return st.fixed_dictionaries(fields)


def _items(item, n=6):
    return st.lists(item, max_size=n).map(lambda items: {"items": items})


FMON = fmon_layouts()
CASES = (
    (FMON.add, _items(_fmon(False))),
    (FMON.report, _items(_fmon(True))),
    (
        FMON.status,
        _items(
            st.fixed_dictionaries(
                {"fmon": U16, "protected": FLAG, "enabled": FLAG, "checking": st.integers(0, 3)}
            )
        ),
    ),
    (FMON.ids, st.lists(U16, max_size=8).map(lambda ids: {"ids": ids})),
    (
        RAW_DEFINITIONS,
        _items(st.fixed_dictionaries({"id": U16, "memory": U16, "address": U32})),
    ),
    (
        OBJECT_DEFINITIONS,
        _items(st.fixed_dictionaries({"id": U16, "memory": U16, "object": U16, "offset": U32})),
    ),
    (
        DEFINITION_REPORT,
        _items(
            st.fixed_dictionaries(
                {
                    "id": U16,
                    "kind": st.integers(0, 2),
                    "memory": U16,
                    "object": U16,
                    "address": U32,
                }
            )
        ),
    ),
)


@SETTINGS
@given(st.data())
def test_messages_round_trip(data):
    for layout, values in CASES:
        v = data.draw(values)
        assert layout.unpack(layout.pack(v)) == v


@SETTINGS
@given(st.binary(max_size=64))
def test_junk_raises_only_decode_errors(junk):
    for layout, _ in CASES:
        try:
            layout.unpack(junk)
        except DECODE_ERRORS:
            pass


@SETTINGS
@given(
    st.floats(-100, 100, allow_nan=False).filter(lambda c: c != 0),
    st.floats(-1000, 1000, allow_nan=False),
    st.integers(0, 0xFFFF),
)
def test_linear_calibrations_invert(c1, c0, raw):
    assume(abs(c1) > 1e-3)
    v = Values(field(3, 12), {"calibration": {"polynomial": [c0, c1]}})
    assert v.to_raw(v.engineering(raw)) == raw


@SETTINGS
@given(
    st.lists(st.integers(-1000, 1000), min_size=2, max_size=6, unique=True),
    st.floats(0, 1),
)
def test_monotonic_splines_invert(raws, where):
    raws.sort()
    points = [[r, 3.0 * r + 7] for r in raws]
    cal = calibration({"spline": points})
    raw = raws[0] + where * (raws[-1] - raws[0])
    assert abs(cal.raw(cal.engineering(raw)) - raw) < 1e-6


@SETTINGS
@given(st.integers(-5000, 5000), st.integers(-5000, 5000), st.integers(-0x8000, 0x7FFF))
def test_raw_limits_agree_with_engineering_limits(a, b, raw):
    low, high = min(a, b) / 10.0, max(a, b) / 10.0
    for coeffs in ([3.0, 0.25], [-2.0, -0.5]):
        v = Values(field(4, 12), {"calibration": {"polynomial": coeffs}})
        raw_low, raw_high, _ = v.raw_limits(low, high)
        eng = v.engineering(raw)
        assert (raw_low <= raw <= raw_high) == (low <= eng <= high)
