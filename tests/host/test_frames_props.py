"""Property tests for obsw.frames: round trips, correction, robustness, COP-1 on bad links."""

import random

from hypothesis import given, settings
from hypothesis import strategies as st
from obsw.frames import asm, cltu, farm, processor, tc, tm, tm_demux, tm_mux
from obsw.frames import fop as F
from obsw.frames.clcw import Clcw
from obsw.frames.errors import FrameError

SETTINGS = settings(max_examples=200, deadline=None)


def tm_packet(apid, payload):
    n = len(payload)
    return bytes((0x08 | apid >> 8, apid & 0xFF, 0xC0, 0, (n - 1) >> 8, (n - 1) & 0xFF)) + payload


packets = st.lists(
    st.tuples(st.integers(0, 0x7FE), st.binary(min_size=1, max_size=300)).map(
        lambda t: tm_packet(*t)
    ),
    max_size=12,
)


@SETTINGS
@given(packets, st.integers(20, 300), st.booleans(), st.lists(st.booleans(), max_size=12))
def test_any_packet_stream_comes_out_of_tm_frames_identical(pkts, length, ocf, flushes):
    vc = tm_mux.TmVirtualChannel(0)
    mux = tm_mux.TmMultiplexer(9, length, [vc], (lambda: b"\x00\x01\x02\x03") if ocf else None)
    demux = tm_demux.TmDemultiplexer(9)
    dec = asm.CaduDecoder(length)
    got = []
    for i, p in enumerate(pkts):
        vc.push(p)
        flush = flushes[i] if i < len(flushes) else False
        while True:
            f = mux.frame(flush)
            if f is None:
                break
            for raw in dec.feed(asm.cadu(f.pack())):
                got.extend(demux.feed(raw))
    while vc.pending():
        got.extend(demux.feed(mux.frame(True).pack()))
    assert got == pkts


@SETTINGS
@given(
    st.integers(0, 1023),
    st.integers(0, 63),
    st.binary(max_size=1017),
    st.integers(0, 255),
    st.booleans(),
    st.booleans(),
)
def test_tc_frame_round_trip(scid, vcid, data, seq, bypass, control):
    f = tc.TcFrame(scid, vcid, data, seq, bypass, control)
    g = tc.TcFrame.unpack(f.pack())
    assert (g.scid, g.vcid, g.data, g.seq, g.bypass, g.control) == (
        scid,
        vcid,
        data,
        seq,
        bypass,
        control,
    )


@SETTINGS
@given(
    st.integers(0, 1023),
    st.integers(0, 7),
    st.binary(max_size=200),
    st.integers(0, 255),
    st.integers(0, 255),
    st.integers(0, 2047),
    st.one_of(st.none(), st.binary(min_size=4, max_size=4)),
    st.one_of(st.none(), st.binary(min_size=1, max_size=63)),
)
def test_tm_frame_round_trip(scid, vcid, data, mc, vcc, fhp, ocf, sh):
    f = tm.TmFrame(scid, vcid, data, mc, vcc, fhp, ocf, sh)
    g = tm.TmFrame.unpack(f.pack())
    assert (g.scid, g.vcid, g.data, g.mc_count, g.vc_count, g.fhp, g.ocf, g.secondary_header) == (
        scid,
        vcid,
        data,
        mc,
        vcc,
        fhp,
        ocf,
        sh,
    )


@SETTINGS
@given(st.binary(min_size=1, max_size=400), st.booleans(), st.data())
def test_cltu_corrects_one_bit_error_per_codeblock(frame, randomize, data):
    c = bytearray(cltu.encode(frame, randomize))
    blocks = (len(c) - 10) // 8
    flips = 0
    for k in range(blocks):
        if data.draw(st.booleans()):
            bit = data.draw(st.integers(0, 62))
            c[2 + 8 * k + (bit >> 3)] ^= 0x80 >> (bit & 7)
            flips += 1
    out, fixed = cltu.decode(bytes(c), randomize)
    assert out[: len(frame)] == frame
    assert fixed == flips


@SETTINGS
@given(st.binary(max_size=300))
def test_random_bytes_raise_only_declared_errors(blob):
    decoders = (
        lambda b: tc.TcFrame.unpack(b),
        lambda b: tc.TcFrame.unpack(b, trailing=True),
        lambda b: tm.TmFrame.unpack(b),
        lambda b: tm.TmFrame.unpack(b, fecf=False),
        Clcw.unpack,
        cltu.decode,
        tc.Segment.unpack,
        tc.parse_control_command,
        lambda b: tm_demux.TmDemultiplexer(5).feed(b),
        lambda b: tm_demux.TmDemultiplexer(5, fecf=False).feed(b),
    )
    for decode in decoders:
        try:
            decode(blob)
        except FrameError:
            pass
    # Stream decoders never raise: they skip and count.
    cltu.CltuDecoder().feed(blob)
    asm.CaduDecoder(20).feed(blob)
    p = processor.FrameProcessor(5, lambda a, b: None, tc_vcids=(0, 1))
    p.receive(0, blob, 0.0)
    p.receive(1, b"\xeb\x90" + blob, 0.0)
    p.on_frame_data(0, blob, 0.0)


@SETTINGS
@given(st.binary(min_size=6, max_size=2000))
def test_random_frame_data_through_extractor(blob):
    demux = tm_demux.TmDemultiplexer(5, fecf=False)
    for i in range(0, len(blob) - 6, 50):
        chunk = bytearray(blob[i : i + 50])
        if len(chunk) < 6:
            break
        chunk[0] = 0  # scid 5, version 0
        chunk[1] = 0x50
        chunk[4] = (chunk[4] & 0x27) | 0x18
        try:
            demux.feed(bytes(chunk))
        except FrameError:
            pass


@settings(max_examples=60, deadline=None)
@given(
    st.integers(0, 2**32 - 1),
    st.integers(0, 30),
    st.integers(0, 30),
    st.integers(0, 50),
    st.integers(0, 3),
    st.integers(1, 5),
)
def test_cop1_delivers_every_frame_once_in_order(seed, loss, dup, clcw_loss, reorder, k):
    rng = random.Random(seed)
    fop = F.Fop1(1, 0, window=k, t1=1.0, transmission_limit=10000)
    fa = farm.Farm1(0, window=10)
    fop.directive(F.INITIATE_AD_NO_CLCW, now=0)
    todo = [b"%03d" % i for i in range(25)]
    delivered, uplink, downlink = [], [], []
    newest = -1
    now = 0.0
    sent = 0  # frames put on the uplink so far
    for step in range(40000):
        now += 0.05
        if todo and fop.ready:
            fop.send_ad(todo.pop(0), now)
        for fr in fop.take_frames():
            if rng.randrange(100) < loss:
                continue
            for _ in range(1 + (rng.randrange(100) < dup)):
                # a frame overtakes at most `reorder` frames sent before it: the link reorders
                # but does not hold a frame back indefinitely, which COP-1 assumes (a frame older
                # than FARM's negative window would rightly cause Lockout)
                sent += 1
                uplink.append((sent - rng.randint(0, reorder), sent, fr))
        uplink.sort(key=lambda e: e[:2])
        for _ in range(min(3, len(uplink))):
            fa.on_frame(uplink.pop(0)[2])
            while (got := fa.take()) is not None:
                delivered.append(got.data)
            if rng.randrange(100) >= clcw_loss:
                downlink.insert(rng.randint(0, len(downlink)), (step, fa.clcw()))
        if downlink and rng.randrange(2):
            seq, c = downlink.pop(0)
            if seq > newest:
                newest = seq
                fop.on_clcw(c, now)
        fop.tick(now)
        for n in fop.take_notifications():
            assert n[0] not in (F.ALERT, F.SUSPEND), n
        if not todo and fop.outstanding == 0:
            break
    assert delivered == [b"%03d" % i for i in range(25)]
