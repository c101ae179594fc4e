"""CBOR properties: round trips, determinism, byte-identity with cbor2's canonical encoder,
interop with cbor2 both ways, and malformed input raising only CborDecodeError."""

import math
import random

import cbor2
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from obsw import cbor
from obsw.cbor import UNDEFINED, CborDecodeError, Simple, Tag
from obsw_host.il import wire

SETTINGS = settings(max_examples=200, deadline=None)

ints = st.one_of(
    st.integers(min_value=-(2**64) - 2, max_value=2**64 + 2),
    st.integers(min_value=-(2**200), max_value=2**200),
)
floats = st.floats(allow_nan=False)
scalars = st.one_of(
    ints, floats, st.text(max_size=40), st.binary(max_size=40), st.booleans(), st.none()
)
keys = st.one_of(
    st.integers(min_value=-(2**70), max_value=2**70),
    st.text(max_size=12),
    st.binary(max_size=12),
    st.tuples(st.integers(), st.text(max_size=4)),
)
values = st.recursive(
    scalars,
    lambda inner: st.one_of(st.lists(inner, max_size=6), st.dictionaries(keys, inner, max_size=6)),
    max_leaves=24,
)


def same(a, b):
    """Equality that treats NaN as equal to NaN and lists and tuples alike."""
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    return a == b and type(a) is type(b)


@SETTINGS
@given(values)
def test_round_trip(v):
    assert same(cbor.loads(cbor.dumps(v)), v)


@SETTINGS
@given(st.floats())
def test_floats_round_trip_in_shortest_form(x):
    enc = cbor.dumps(x)
    assert same(cbor.loads(enc), x)
    assert enc == cbor2.dumps(x, canonical=True)
    assert len(enc) in (3, 5, 9)


@SETTINGS
@given(st.dictionaries(keys, st.integers(), max_size=10), st.randoms())
def test_map_order_does_not_change_bytes(d, rnd):
    items = list(d.items())
    rnd.shuffle(items)
    assert cbor.dumps(dict(items)) == cbor.dumps(d)


@SETTINGS
@given(values)
def test_same_bytes_as_cbor2_canonical(v):
    assert cbor.dumps(v) == cbor2.dumps(v, canonical=True)
    assert wire.dumps(v) == cbor.dumps(v)


@SETTINGS
@given(values)
def test_cbor2_decodes_ours(v):
    assert same(cbor2.loads(cbor.dumps(v)), v)


@SETTINGS
@given(values, st.booleans())
def test_we_decode_cbor2(v, canonical):
    assert same(cbor.loads(cbor2.dumps(v, canonical=canonical)), v)


def test_special_values_through_the_wire_encoder():
    for v in (UNDEFINED, Tag(99, [1, b"x"]), Simple(99), [Simple(0), {1: UNDEFINED}]):
        assert wire.dumps(v) == cbor.dumps(v)
        assert cbor.loads(cbor.dumps(v)) == v
    assert wire.loads(cbor.dumps(Tag(99, 1))) == Tag(99, 1)


def test_wire_refuses_what_cbor_cannot_carry():
    with pytest.raises(cbor.CborEncodeError):
        wire.dumps({1: object()})
    with pytest.raises(cbor.CborEncodeError):
        cbor.dumps({1: object()})


@SETTINGS
@given(st.binary(max_size=64))
def test_random_bytes_raise_only_decode_error(data):
    for decode in (cbor.loads, wire.loads):
        try:
            decode(data)
        except CborDecodeError:
            pass


@SETTINGS
@given(values, st.data())
def test_damaged_encodings_raise_only_decode_error(v, data):
    enc = bytearray(cbor.dumps(v))
    cut = data.draw(st.integers(min_value=0, max_value=len(enc) - 1))
    with pytest.raises(CborDecodeError):
        cbor.loads(bytes(enc[:cut]))
    i = data.draw(st.integers(min_value=0, max_value=len(enc) - 1))
    enc[i] = data.draw(st.integers(min_value=0, max_value=255))
    for decode in (cbor.loads, wire.loads):
        try:
            decode(bytes(enc))
        except CborDecodeError:
            pass


@SETTINGS
@given(st.lists(values, min_size=1, max_size=5), st.randoms())
def test_frames_split_anywhere(msgs, rnd):
    stream = b"".join(wire.frame(m) for m in msgs)
    reader = wire.FrameReader()
    got = []
    pos = 0
    while pos < len(stream):
        step = rnd.randint(1, 7)
        got.extend(reader.feed(stream[pos : pos + step]))
        pos += step
    assert len(got) == len(msgs)
    assert all(same(a, b) for a, b in zip(got, msgs))
    assert reader.pending() == 0


def test_oversized_frame_refused():
    reader = wire.FrameReader()
    with pytest.raises(wire.FrameError):
        reader.feed((wire.MAX_FRAME + 1).to_bytes(4, "big"))


def test_il_messages_are_compact_and_keep_types():
    msg = [1, 7, "SolarPanel", "set_angle", [30.0, b"\x01\x02", {1: "int key"}], ["A"]]
    enc = cbor.dumps(msg)
    assert cbor.loads(enc) == msg
    assert len(enc) < len(repr(msg))


def test_deep_random_structures():
    rnd = random.Random(5)
    for _ in range(50):
        v = []
        for _ in range(rnd.randint(1, 30)):
            v = [v] if rnd.random() < 0.5 else {rnd.randint(0, 9): v}
        assert same(cbor.loads(cbor.dumps(v)), v)
