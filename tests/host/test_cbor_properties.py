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


# the C framing and decoding of obsw_speedups against cbor2 and the core codec
C = wire._C
needs_c = pytest.mark.skipif(C is None, reason="obsw_speedups not built, OBSW_PURE or core codec")
DECLINED = object()


@needs_c
@SETTINGS
@given(values)
def test_c_frame_is_cbor2_canonical_or_declines(v):
    data = C.cbor_frame(v)
    body = cbor2.dumps(v, canonical=True)
    assert data is None or data == len(body).to_bytes(4, "big") + body
    assert wire.frame(v) == len(body).to_bytes(4, "big") + body
    assert body == cbor.dumps(v)


@needs_c
@SETTINGS
@given(values, st.booleans())
def test_c_decodes_like_cbor2_or_declines(v, canonical):
    body = cbor2.dumps(v, canonical=canonical)
    got = C.cbor_loads(body, DECLINED)
    assert got is DECLINED or same(got, cbor2.loads(body))
    assert same(wire.loads(body), cbor2.loads(body))


@needs_c
@SETTINGS
@given(st.binary(max_size=64))
def test_c_decoder_on_random_bytes_agrees_or_declines(data):
    got = C.cbor_loads(data, DECLINED)
    if got is not DECLINED:
        assert same(got, cbor2.loads(data))


@needs_c
def test_c_path_declines_what_only_python_knows():
    for v in (2**64, -(2**64) - 1, Tag(5, 1), UNDEFINED, Simple(99), memoryview(b"ab")):
        assert C.cbor_frame(v) is None, v
    deep = []
    for _ in range(20):
        deep = [deep]
    assert C.cbor_frame(deep) is None  # deeper than the C path goes: Python decides
    assert wire.frame(deep)[4:] == cbor.dumps(deep)
    assert C.cbor_loads(cbor.dumps(Tag(99, 1)), DECLINED) is DECLINED
    assert C.cbor_loads(b"\x9f\xff", DECLINED) is DECLINED  # indefinite length
    assert C.cbor_loads(b"\x62\xff\xfe", DECLINED) is DECLINED  # not UTF-8
    assert C.cbor_loads(b"\xa1\x81\x01\x02", DECLINED) is DECLINED  # array as a map key
    assert C.cbor_loads(b"\x01\x02", DECLINED) is DECLINED  # trailing data
    with pytest.raises(cbor.CborDecodeError):
        wire.loads(b"\x62\xff\xfe")


@needs_c
@SETTINGS
@given(values, st.booleans())
def test_c_whole_frame_decodes_like_the_reader_or_declines(v, canonical):
    body = cbor2.dumps(v, canonical=canonical)
    data = len(body).to_bytes(4, "big") + body
    got = C.cbor_frame_loads(data, DECLINED, wire.MAX_FRAME)
    assert got is DECLINED or same(got, cbor2.loads(body))
    assert [same(m, cbor2.loads(body)) for m in wire.FrameReader().feed(data)] == [True]


@needs_c
@SETTINGS
@given(st.binary(max_size=64))
def test_c_whole_frame_on_random_bytes_agrees_or_declines(data):
    got = C.cbor_frame_loads(data, DECLINED, wire.MAX_FRAME)
    if got is not DECLINED:
        assert len(data) >= 5 and int.from_bytes(data[:4], "big") == len(data) - 4
        assert same(got, cbor2.loads(data[4:]))


@needs_c
def test_c_whole_frame_declines_anything_but_one_whole_frame():
    one = wire.frame([1, "a"])
    for data in (one + one, one[:-1], one[:4], b"", bytearray(one[:3])):
        assert C.cbor_frame_loads(data, DECLINED, wire.MAX_FRAME) is DECLINED
    assert C.cbor_frame_loads(one, DECLINED, 1) is DECLINED  # above the frame limit
    assert C.cbor_frame_loads(bytearray(one), DECLINED, wire.MAX_FRAME) == [1, "a"]
    assert C.cbor_frame_loads(memoryview(one), DECLINED, wire.MAX_FRAME) == [1, "a"]
