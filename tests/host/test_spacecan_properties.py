"""Property tests for the SpaceCAN codecs: round trips, junk only raising declared errors."""

from hypothesis import given, settings
from hypothesis import strategies as st
from obsw.spacecan import encoding as enc
from obsw.spacecan import packets as pk
from obsw.spacecan.fragment import MAX_PACKET_SIZE, Reassembler, split
from obsw.spacecan.nodedef import NodeDefinition
from obsw.spacecan.timeframes import CanFrameLengthError, ScetTime, UtcTime

NODE = NodeDefinition.from_dict(
    {
        "parameters": [
            {"parameter_id": i, "parameter_name": "p%d" % i, "encoding": e, "value": 0}
            for i, e in enumerate(enc.NAMES)
        ],
        "housekeeping_reports": [
            {"report_id": 1, "interval": 1, "enabled": False, "parameter_ids": [1, 2, 3, 9]}
        ],
        "functions": [
            {
                "function_id": 1,
                "function_name": "f",
                "arguments": [
                    {"argument_id": 1, "argument_name": "a", "encoding": "u8"},
                    {"argument_id": 2, "argument_name": "b", "encoding": "f64"},
                ],
            }
        ],
    }
)


@settings(max_examples=200, deadline=None)
@given(st.binary(max_size=MAX_PACKET_SIZE))
def test_split_reassemble(data):
    r = Reassembler()
    out = [p for p in (r.push(1, f, 0.0) for f in split(data)) if p is not None]
    assert out == [data]


@settings(max_examples=200, deadline=None)
@given(
    st.lists(st.tuples(st.integers(0, 3), st.binary(max_size=8)), max_size=60),
    st.binary(max_size=40),
)
def test_junk_never_blocks_next_packet(junk, data):
    r = Reassembler()
    for key, frame in junk:
        r.push(key, frame, 0.0)
    out = [p for p in (r.push(1, f, 0.0) for f in split(data)) if p is not None]
    assert out == [data]


_INT = {"i8": 8, "i16": 16, "i32": 32, "i64": 64}


@settings(max_examples=200, deadline=None)
@given(st.data())
def test_encoding_round_trip(d):
    name = d.draw(st.sampled_from(enc.NAMES))
    if name == "bool":
        v = d.draw(st.booleans())
    elif name.startswith("i"):
        bits = _INT[name]
        v = d.draw(st.integers(-(1 << (bits - 1)), (1 << (bits - 1)) - 1))
    elif name.startswith("u"):
        v = d.draw(st.integers(0, (1 << int(name[1:])) - 1))
    elif name == "f32":
        v = d.draw(st.floats(width=32, allow_nan=False))
    else:
        v = d.draw(st.floats(allow_nan=False))
    assert enc.decode(name, enc.encode(name, v)) == (v, enc.size(name))


@settings(max_examples=200, deadline=None)
@given(st.binary(max_size=40))
def test_service_payload_junk(data):
    for fn in (
        pk.unpack_ids,
        lambda b: pk.unpack_values(NODE, b),
        lambda b: pk.unpack_hk(NODE, b),
        lambda b: pk.unpack_function(NODE, b),
    ):
        try:
            fn(data)
        except pk.ServicePacketError:
            pass


@settings(max_examples=200, deadline=None)
@given(
    st.integers(0, (1 << 32) - 1),
    st.integers(0, (1 << 24) - 1),
    st.integers(0, 65535),
    st.integers(0, 65535),
)
def test_time_frames_round_trip(coarse, fine, day, sub):
    assert ScetTime.unpack(ScetTime(coarse, fine).pack()) == ScetTime(coarse, fine)
    assert UtcTime.unpack(UtcTime(day, coarse, sub).pack()) == UtcTime(day, coarse, sub)


@settings(max_examples=100, deadline=None)
@given(st.binary(max_size=12))
def test_time_frame_junk(data):
    for cls in (ScetTime, UtcTime):
        try:
            cls.unpack(data)
        except CanFrameLengthError:
            pass
