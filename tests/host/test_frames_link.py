"""The frame processor process on two pty pairs, with the ground's FOP-1 and TM decoding."""

import socket
import threading
import time

import pytest
from obsw.frames import fop as F
from obsw.frames.cltu import encode
from obsw.frames.tc import Segment, TcFrame
from obsw_host.frames.ground import Ground
from obsw_host.frames.links import FdLink, SerialLink, open_pty_pair
from obsw_host.frames.processor import FrameProcessorHost
from obsw_host.net import DEFAULT_HOST

SCID = 0x33
APID = 0x40
LENGTH = 96


def tc_packet(seq, payload):
    n = len(payload)
    return bytes((0x18, APID, 0xC0 | seq >> 8, seq & 0xFF, 0, n - 1)) + payload


@pytest.fixture
def rig():
    ctrl_a, dev_a = open_pty_pair()
    ctrl_b, dev_b = open_pty_pair()
    app = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    app.bind(("127.0.0.1", 0))
    app.settimeout(0)
    port = app.getsockname()[1]
    obc = FrameProcessorHost(
        SerialLink(dev_a),
        SerialLink(dev_b),
        SCID,
        routes={APID: (DEFAULT_HOST, port)},
        tm_port=0,
        tm_frame_length=LENGTH,
        clcw_period=0.2,
        essential_map=63,
    )
    stop = threading.Event()
    worker = threading.Thread(target=obc.run, args=(stop,), daemon=True)
    worker.start()
    flips = []

    def corrupt(link, cltu):
        if not flips:
            return cltu
        bit = flips.pop(0)
        if bit is None:
            return cltu
        damaged = bytearray(cltu)
        damaged[2 + (bit >> 3)] ^= 0x80 >> (bit & 7)
        return bytes(damaged)

    ground = Ground(
        [FdLink(ctrl_a), FdLink(ctrl_b)], SCID, tm_frame_length=LENGTH, corrupt=corrupt, t1=1.0
    )
    t0 = time.monotonic()
    received = []

    def pump(until, limit=10.0):
        end = time.monotonic() + limit
        while time.monotonic() < end:
            ground.poll(time.monotonic() - t0, 0.01)
            try:
                while True:
                    pkt = app.recv(65536)
                    received.append(pkt)
                    app.sendto(b"\x08" + pkt[1:], ("127.0.0.1", obc.tm_port))  # echo as TM
            except BlockingIOError:
                pass
            if until():
                return True
        return False

    class Rig:
        pass

    r = Rig()
    r.obc, r.ground, r.pump, r.received, r.flips = obc, ground, pump, received, flips
    r.now = lambda: time.monotonic() - t0
    yield r
    stop.set()
    worker.join(2)
    obc.close()
    for link in ground.links:
        link.close()
    app.close()


def test_commands_delivered_once_with_bit_errors_and_echoed(rig):
    rig.ground.initiate(rig.now())
    assert rig.pump(lambda: rig.ground.fop.state == F.ACTIVE)
    sent = [tc_packet(i, b"payload %d" % i) for i in range(6)]
    for i, pkt in enumerate(sent):
        rig.flips.extend([i * 7 % 63, (i * 13 + 5) % 63])  # one bit on each link
        rig.ground.send(pkt, rig.now())
    counters = rig.obc.core.counters
    assert rig.pump(
        lambda: len(rig.ground.packets) == 6 and rig.ground.idle and counters["duplicates"] == 7
    )
    assert rig.received == sent
    assert [b"\x18" + p[1:] for p in rig.ground.packets] == sent
    c = rig.obc.core.counters
    assert c["corrected_bits"] == 12
    assert c["duplicates"] == 7  # the Unlock BC frame and the six AD frames
    assert c["packets_routed"] == 6
    assert rig.ground.demux.clcw.report == 6


def test_link_cut_loses_nothing(rig):
    rig.ground.initiate(rig.now())
    counters = rig.obc.core.counters
    # Wait for both copies of the Unlock frame before cutting link A.
    assert rig.pump(lambda: rig.ground.fop.state == F.ACTIVE and counters["duplicates"] == 1)
    rig.ground.links[0].enabled = False
    rig.obc.links[0].enabled = False
    before = rig.obc.core.counters["duplicates"]
    for i in range(3):
        rig.ground.send(tc_packet(i, b"x"), rig.now())
    assert rig.pump(lambda: len(rig.ground.packets) == 3 and rig.ground.idle)
    assert len(rig.received) == 3
    assert rig.obc.core.counters["duplicates"] == before


def test_uncorrectable_cltu_is_retransmitted_by_fop(rig):
    rig.ground.initiate(rig.now())
    assert rig.pump(lambda: rig.ground.fop.state == F.ACTIVE)
    rig.ground.links[1].enabled = False
    rig.flips.extend([3])
    orig = rig.ground.corrupt

    def double(link, cltu):
        out = bytearray(orig(link, cltu))
        if len(rig.received) == 0 and not getattr(double, "done", False):
            out[3] ^= 0x01  # second bit in the same codeblock: uncorrectable
            double.done = True
        return bytes(out)

    rig.ground.corrupt = double
    rig.ground.send(tc_packet(0, b"again"), rig.now())
    assert rig.pump(lambda: len(rig.received) == 1 and rig.ground.idle)
    assert rig.obc.core.counters["cltus_aborted"] == 1
    assert rig.ground.fop.transmission_count == 1
    assert len(rig.ground.sent_frames) >= 3  # BC unlock, the AD frame, its retransmission


def test_high_priority_command_goes_to_essential_sink(rig):
    frame = TcFrame(SCID, 0, Segment(63, tc_packet(0, b"HPC")).pack(), 0, True)
    for link in rig.ground.links:
        link.write(encode(frame.pack()))
    assert rig.pump(lambda: rig.obc.essential)
    assert rig.obc.essential == [tc_packet(0, b"HPC")]
    assert rig.received == []


def test_demo_runs():
    import frames_demo as demo

    lines = []
    assert demo.run(lines.append) == 0
    text = "\n".join(lines)
    assert "1 bit(s) corrected" in text
    assert "every TC delivered once" in text


def test_cli_cltu_round_trip(capsys):
    from obsw_host.commands import frames

    class A:
        pass

    a = A()
    a.hex, a.randomize = "302a00070000ea16", True
    frames.cltu_encode(a)
    encoded = capsys.readouterr().out.strip()
    assert encoded.startswith("eb90") and encoded.endswith("c5c5c5c5c5c5c579")
    a.hex = encoded
    frames.cltu_decode(a)
    assert '"type": "BC"' in capsys.readouterr().out
