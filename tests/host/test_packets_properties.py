"""Property tests for space packets and PUS-C packets: round trips, decode errors, the stream."""

from hypothesis import given
from hypothesis import strategies as st
from obsw import spp
from obsw.crc import crc16_ccitt
from obsw.pus.any_packet import unpack_packet
from obsw.pus.config import PusConfig
from obsw.pus.packets import PusError
from obsw.pus.tc import PusTc
from obsw.pus.tm import PusTm
from obsw.timecode import Cds, Cuc

apids = st.integers(0, 0x7FF)
counts = st.integers(0, 0x3FFF)
flags = st.integers(0, 3)
octets = st.integers(0, 255)
small_data = st.binary(max_size=80)


@st.composite
def space_packets(draw):
    return spp.SpacePacket(
        draw(st.integers(0, 1)),
        draw(apids),
        draw(st.binary(min_size=1, max_size=200)),
        draw(st.booleans()),
        draw(flags),
        draw(counts),
    )


time_codes = st.one_of(
    st.none(),
    st.builds(Cuc, st.integers(1, 7), st.integers(0, 4), st.none(), st.booleans()),
    st.builds(Cds, st.sampled_from([2, 3]), st.sampled_from([0, 2, 4])),
)


@st.composite
def configs(draw):
    return PusConfig(
        source_id_size=draw(st.integers(0, 4)),
        destination_id_size=draw(st.integers(0, 4)),
        message_counter_size=draw(st.integers(0, 2)),
        time=draw(time_codes),
        pec=draw(st.booleans()),
        tc_spare=draw(st.integers(0, 3)),
        tm_spare=draw(st.integers(0, 3)),
    )


def _time_value(draw, code):
    if code is None:
        return None
    if isinstance(code, Cuc):
        return (
            draw(st.integers(0, (1 << (8 * code.coarse)) - 1)),
            draw(st.integers(0, (1 << (8 * code.fine)) - 1)),
        )
    return (
        draw(st.integers(0, (1 << (8 * code.day_octets)) - 1)),
        draw(st.integers(0, 86400999)),
        draw(st.integers(0, max(code.sub_per_ms - 1, 0))),
    )


@st.composite
def tcs(draw, config=None):
    c = config if config is not None else draw(configs())
    return PusTc(
        draw(apids),
        draw(octets),
        draw(octets),
        draw(small_data),
        draw(counts),
        draw(st.integers(0, 15)),
        draw(st.integers(0, c.source_id_max)),
        draw(flags),
        c,
    )


@st.composite
def tms(draw, config=None):
    c = config if config is not None else draw(configs())
    return PusTm(
        draw(apids),
        draw(octets),
        draw(octets),
        draw(small_data),
        draw(counts),
        draw(st.integers(0, c.message_counter_max)),
        draw(st.integers(0, c.destination_id_max)),
        _time_value(draw, c.time),
        draw(st.integers(0, 15)),
        draw(flags),
        c,
    )


@given(space_packets())
def test_space_packet_round_trip(p):
    raw = p.pack()
    assert len(raw) == 6 + len(p.data)
    back = spp.SpacePacket.unpack(raw)
    assert back == p
    assert spp.PrimaryHeader.unpack(raw).pack() == raw[:6]


@given(st.binary(max_size=40))
def test_space_packet_random_bytes(buf):
    try:
        p, end = spp.SpacePacket.unpack_from(buf)
    except spp.SppError:
        return
    assert end == len(p) <= len(buf)


@given(tcs())
def test_tc_round_trip(tc):
    raw = tc.pack()
    back = PusTc.unpack(raw, tc.config)
    assert back == tc
    assert len(raw) == tc.config.tc_min_size + len(tc.data)
    if tc.config.pec:
        assert crc16_ccitt(raw) == 0


@given(tms())
def test_tm_round_trip(tm):
    raw = tm.pack()
    back = PusTm.unpack(raw, tm.config)
    assert back == tm
    assert back.time == tm.time or (tm.time is None and not any(back.time))


def _decoders(buf, config):
    for decode in (PusTc.unpack, PusTm.unpack, unpack_packet):
        try:
            decode(buf, config)
        except PusError:
            pass


@given(st.binary(max_size=60), configs())
def test_random_bytes_raise_only_pus_errors(buf, config):
    _decoders(buf, config)


@given(st.binary(min_size=4, max_size=60), configs(), st.integers(0, 1))
def test_random_bodies_with_valid_pec(body, config, kind):
    # a consistent primary header and a correct CRC push the decoders past the early checks
    n = len(body) + 6 + 2 - 1
    head = bytes([0x08 | (kind << 4) | (body[0] & 0x07), body[1], body[2], body[3] & 0x3F])
    raw = head + bytes([n >> 8, n & 0xFF]) + body
    c = crc16_ccitt(raw)
    _decoders(raw + bytes([c >> 8, c & 0xFF]), config)


def _valid(raw):
    return crc16_ccitt(raw) == 0


@given(
    st.lists(st.tuples(st.binary(max_size=30), tcs(PusConfig())), min_size=1, max_size=5),
    st.integers(1, 64),
)
def test_stream_never_loses_packets_after_garbage(items, chunk):
    stream = spp.PacketStream(max_length=300, validate=_valid)
    sent = []
    data = b""
    for garbage, tc in items:
        raw = tc.pack()
        sent.append(raw)
        data += garbage + raw
    got = []
    for i in range(0, len(data), chunk):
        got.extend(stream.feed(data[i : i + chunk])[0])
    got.extend(stream.flush()[0])
    # every packet sent comes out, in order (garbage may by chance add packets of its own)
    it = iter(got)
    assert all(any(g == s for g in it) for s in sent)
    assert stream.pending == 0


@given(st.lists(tms(PusConfig()), min_size=1, max_size=6), st.integers(1, 50))
def test_stream_clean_input_skips_nothing(packets, chunk):
    stream = spp.PacketStream(validate=_valid)
    data = b"".join(p.pack() for p in packets)
    got = []
    total_skipped = 0
    for i in range(0, len(data), chunk):
        out, skipped = stream.feed(data[i : i + chunk])
        got.extend(out)
        total_skipped += skipped
    assert got == [p.pack() for p in packets]
    assert total_skipped == 0 and stream.pending == 0
