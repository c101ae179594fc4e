"""Interop: field types and time codes against puslib (and spacepackets' CDS), both directions."""

import struct

import puslib.parameter as puslib_parameter
import puslib.time as puslib_time
import spacepackets.ccsds.time as sp_time
from hypothesis import given, settings
from hypothesis import strategies as st
from obsw.pus.fields import field
from obsw.timecode import Cds, Cuc

SETTINGS = settings(max_examples=200, deadline=None)
P = puslib_parameter

# (our field type, puslib class) pairs for the parameter types puslib implements
INTEGERS = [
    (field(3, 4), P.UInt8Parameter, 0, 2**8 - 1),
    (field(3, 12), P.UInt16Parameter, 0, 2**16 - 1),
    (field(3, 14), P.UInt32Parameter, 0, 2**32 - 1),
    (field(3, 16), P.UInt64Parameter, 0, 2**64 - 1),
    (field(4, 4), P.Int8Parameter, -(2**7), 2**7 - 1),
    (field(4, 12), P.Int16Parameter, -(2**15), 2**15 - 1),
    (field(4, 14), P.Int32Parameter, -(2**31), 2**31 - 1),
    (field(4, 16), P.Int64Parameter, -(2**63), 2**63 - 1),
]


@st.composite
def _integer_case(draw):
    ours, theirs, lo, hi = draw(st.sampled_from(INTEGERS))
    return ours, theirs, draw(st.integers(lo, hi))


@SETTINGS
@given(_integer_case())
def test_integers_both_directions(case):
    ours, theirs, value = case
    data = ours.pack(value)
    assert bytes(theirs(value)) == data
    assert theirs.from_bytes(data) == value
    assert ours.unpack(bytes(theirs(value))) == value


@SETTINGS
@given(st.sampled_from((8, 16, 32, 64)), st.data())
def test_enumerated_both_directions(bits, data):
    value = data.draw(st.integers(0, 2**bits - 1))
    ours = field(2, bits)
    assert bytes(P.EnumParameter(value, bits)) == ours.pack(value)
    assert P.EnumParameter.from_bytes(ours.pack(value), bits) == value
    assert ours.unpack(bytes(P.EnumParameter(value, bits))) == value


@SETTINGS
@given(st.booleans())
def test_boolean_octet_both_directions(value):
    # puslib's boolean is one octet (its PFC 8)
    ours = field(1, 8)
    assert bytes(P.BoolParameter(value)) == ours.pack(value)
    assert P.BoolParameter.from_bytes(ours.pack(value)) is value
    assert ours.unpack(bytes(P.BoolParameter(value))) is value


@SETTINGS
@given(st.floats(width=32, allow_nan=False), st.floats(allow_nan=False))
def test_reals_both_directions(single, double):
    assert bytes(P.Real32Parameter(single)) == field(5, 1).pack(single)
    assert P.Real32Parameter.from_bytes(field(5, 1).pack(single)) == single
    assert field(5, 1).unpack(bytes(P.Real32Parameter(single))) == single
    assert bytes(P.Real64Parameter(double)) == field(5, 2).pack(double)
    assert P.Real64Parameter.from_bytes(field(5, 2).pack(double)) == double
    assert field(5, 2).unpack(bytes(P.Real64Parameter(double))) == double


@st.composite
def _cuc_case(draw):
    coarse = draw(st.integers(1, 7))
    fine = draw(st.integers(0, 10))
    return (
        coarse,
        fine,
        draw(st.integers(0, 2 ** (8 * coarse) - 1)),
        draw(st.integers(0, 2 ** (8 * fine) - 1)),
    )


@SETTINGS
@given(_cuc_case())
def test_cuc_explicit_both_directions(case):
    coarse, fine, seconds, fraction = case
    ours = Cuc(coarse, fine, explicit=True)
    theirs = puslib_time.CucTime(seconds, fraction, coarse, fine, has_preamble=True)
    assert bytes(theirs) == ours.pack(seconds, fraction)
    back = puslib_time.CucTime.deserialize(ours.pack(seconds, fraction), has_preamble=True)
    assert back.time_field == (seconds, fraction if fine else None)
    assert ours.unpack(bytes(theirs)) == (seconds, fraction)
    # and our P-field parser reads puslib's preamble
    code, size = Cuc.from_pfield(bytes(theirs))
    assert (code.coarse, code.fine, size) == (coarse, fine, len(ours.pfield()))


@SETTINGS
@given(_cuc_case())
def test_cuc_implicit_both_directions(case):
    coarse, fine, seconds, fraction = case
    ours = Cuc(coarse, fine)
    theirs = puslib_time.CucTime(seconds, fraction, coarse, fine, has_preamble=False)
    assert bytes(theirs) == ours.pack(seconds, fraction)
    assert ours.unpack(bytes(theirs)) == (seconds, fraction)
    if fine and coarse + fine >= 2:  # puslib needs a fine part to decode without a P-field
        back = puslib_time.CucTime.deserialize(
            ours.pack(seconds, fraction),
            has_preamble=False,
            basic_unit_length=coarse,
            frac_unit_length=fine,
        )
        assert back.time_field == (seconds, fraction)


@SETTINGS
@given(st.integers(0, 2**16 - 1), st.integers(0, 86399999))
def test_cds_short_against_spacepackets(day, ms):
    ours = Cds(explicit=True)
    theirs = sp_time.CdsShortTimestamp(day, ms, init_dt_unix_stamp=False)
    assert theirs.pack() == ours.pack(day, ms)
    back = sp_time.CdsShortTimestamp.unpack(ours.pack(day, ms))
    assert (back.ccsds_days, back.ms_of_day) == (day, ms)
    assert ours.unpack(theirs.pack()) == (day, ms, 0)
    # the PTC 9 PFC 1 field is the same T-field without the P-field
    assert field(9, 1).pack((day, ms)) == theirs.pack()[1:]


@SETTINGS
@given(st.lists(st.integers(0, 2**32 - 1), min_size=16, max_size=16))
def test_housekeeping_values_match_puslib_struct_format(values):
    # puslib combines parameters through their struct formats; ours must agree byte for byte
    fmt = ">" + "".join(P.UInt32Parameter(v).format.lstrip(">") for v in values)
    data = b"".join(field(3, 14).pack(v) for v in values)
    assert struct.pack(fmt, *values) == data
