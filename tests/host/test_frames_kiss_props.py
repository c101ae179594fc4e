"""Property tests for KISS framing and the paced downlink: round trips whatever the cut, any
octets decode without an exception, and a paced frame processor never loses a packet."""

from hypothesis import given, settings
from hypothesis import strategies as st
from obsw.frames import kiss
from obsw.frames.asm import CaduDecoder
from obsw.frames.processor import FrameProcessor
from obsw.frames.tm import TmFrame
from obsw.frames.tm_demux import TmDemultiplexer
from obsw.frames.tm_mux import TmVirtualChannel

SETTINGS = settings(max_examples=200, deadline=None)


@SETTINGS
@given(st.lists(st.binary(min_size=1, max_size=300), max_size=8), st.integers(0, 15),
       st.lists(st.integers(1, 50), min_size=1, max_size=20))  # fmt: skip
def test_kiss_round_trip_whatever_the_cut(frames, port, cuts):
    stream = b"".join(kiss.encode(f, port) for f in frames)
    d = kiss.KissDecoder()
    got = []
    i = 0
    k = 0
    while i < len(stream):
        n = cuts[k % len(cuts)]
        got += d.feed(stream[i : i + n])
        i += n
        k += 1
    assert got == frames
    assert d.skipped == 0 and d.bad_escapes == 0


@SETTINGS
@given(st.binary(max_size=2000), st.sampled_from([None, 0, 3]))
def test_any_octets_decode_without_an_exception(data, port):
    d = kiss.KissDecoder(port, max_length=64)
    for frame in d.feed(data):
        assert 0 < len(frame) <= 64


def tm_packet(apid, seq, payload):
    n = len(payload)
    return bytes((0x08 | apid >> 8, apid & 0xFF, 0xC0, seq & 0xFF, (n - 1) >> 8,
                  (n - 1) & 0xFF)) + payload  # fmt: skip


@SETTINGS
@given(
    st.lists(
        st.tuples(
            st.sampled_from([0, 1, 2]), st.binary(min_size=1, max_size=120), st.floats(0, 20)
        ),
        max_size=40,
    ),  # fmt: skip
    st.integers(40, 120),
)
def test_paced_downlink_never_loses_a_packet(arrivals, length):
    channels = [TmVirtualChannel(0, 2, 300), TmVirtualChannel(1, 1, 300),
                TmVirtualChannel(2, 0, 300)]  # fmt: skip
    fp = FrameProcessor(0x2A, lambda a, p: None, tm_frame_length=length, tm_channels=channels,
                        downlink_bps=(length + 4) * 8, tm_spill=1 << 20)  # fmt: skip
    dec = CaduDecoder(length)
    demux = TmDemultiplexer(0x2A)
    arrivals = sorted(arrivals, key=lambda a: a[2])
    sent = {0: [], 1: [], 2: []}
    got = {0: [], 1: [], 2: []}
    t = 0.0
    i = 0
    while t < 200.0:
        while i < len(arrivals) and arrivals[i][2] <= t:
            vc, payload, _ = arrivals[i]
            p = tm_packet(0x10 + vc, i, payload)
            assert fp.send_packet(p, vc)
            sent[vc].append(p)
            i += 1
        for c in fp.tm_output(t):
            for raw in dec.feed(c):
                f = TmFrame.unpack(raw)
                got.setdefault(f.vcid, []).extend(demux.on_frame(f))
        if i == len(arrivals) and all(len(got[v]) == len(sent[v]) for v in sent):
            break
        t += 0.25
    assert all(got[v] == sent[v] for v in sent)
    assert fp.counters["tm_dropped"] == 0
