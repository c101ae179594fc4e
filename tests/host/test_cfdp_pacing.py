"""Pacing of a CFDP sender against its UDP link (issue 34): a NAK asking for a run of
segments (the receiver's socket overflowed) halves the file data rate, once per step; NAKs for
single segments (random loss on the link) do not; a rate the sender reaches grows again. The
clock is passed in: nothing here depends on time."""

from obsw.cfdp.filestore import MemoryFilestore
from obsw.cfdp.pdu.header import PduHeader
from obsw.cfdp.pdu.nak import NakPdu
from obsw_host.cfdp import link
from obsw_host.cfdp.link import UdpEntity, make_entity

SEG = 1024


def sender():
    ent = make_entity(1, [2], MemoryFilestore(), segment=SEG, persist=False)
    return UdpEntity(ent, ("127.0.0.1", 0), {2: ("127.0.0.1", 9)}, apid=100)


def nak(*segments):
    return NakPdu(PduHeader(1, 2, 5), 0, 1 << 20, segments)


def test_paced_by_default_and_not_with_a_fixed_rate():
    udp = sender()
    try:
        assert udp.pace and udp.rate == link.PACE_START
    finally:
        udp.close()
    ent = make_entity(1, [2], MemoryFilestore(), segment=SEG, persist=False)
    fixed = UdpEntity(ent, ("127.0.0.1", 0), {2: ("127.0.0.1", 9)}, apid=100, rate=1e5)
    try:
        assert not fixed.pace and fixed.rate == 1e5
    finally:
        fixed.close()


def test_a_run_of_segments_halves_the_rate_single_ones_do_not():
    udp = sender()
    try:
        udp._actual = udp.rate  # it sends at its rate
        udp._window_start = 100.0
        below = (link.PACE_RUN - 1) * SEG
        udp._paced_by(nak((0, SEG), (5 * SEG, 6 * SEG), (SEG * 10, SEG * 10 + below)), 100.0)
        assert udp.rate == link.PACE_START and udp.rate_changes == 0
        run = link.PACE_RUN * SEG
        udp._paced_by(nak((SEG * 20, SEG * 20 + run)), 100.0)
        assert udp.rate == link.PACE_START / 2 and udp.rate_changes == 1
        udp._paced_by(nak((SEG * 40, SEG * 40 + run)), 100.0 + link.PACE_STEP / 2)
        assert udp.rate_changes == 1  # one halving per step
        udp._paced_by(nak((SEG * 60, SEG * 60 + run)), 100.0 + link.PACE_STEP)
        assert udp.rate == link.PACE_START / 4 and udp.rate_changes == 2  # paused: its rate
        udp._window_bytes = int(udp.rate * 0.5 * link.PACE_STEP)  # sent at half its rate
        udp._paced_by(nak((SEG * 80, SEG * 80 + run)), 100.0 + 2 * link.PACE_STEP)
        assert udp.rate == link.PACE_START / 16 and udp.rate_changes == 3  # half what it sent
        udp._paced_by(nak((SEG * 80, SEG * 80 + run)), 100.0 + 3 * link.PACE_STEP)
        assert udp.rate_changes == 3  # the same run asked again (the NAK timer): no news
        for k in range(200):
            start = SEG * 1000 * (k + 1)
            udp._paced_by(nak((start, start + run)), 1e6 + k * link.PACE_STEP)
        assert udp.rate == link.PACE_MIN  # never below
    finally:
        udp.close()


def test_only_a_rate_the_sender_reaches_grows():
    udp = sender()
    try:
        rate = udp.rate
        udp._window_start = 0.0
        udp._window_bytes = int(rate * link.PACE_STEP)  # it sent at its rate
        udp._grow_at = 0.0
        udp._grow(link.PACE_STEP)
        assert udp.rate == rate * 1.1
        udp._window_bytes = 0  # then sent nothing (nothing to send, or no CPU)
        udp._grow(3 * link.PACE_STEP)
        assert udp.rate == rate * 1.1
    finally:
        udp.close()


def test_a_fixed_rate_below_ten_segments_a_second_sends():
    import socket
    import time

    from obsw.spp import SpacePacket

    rx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    rx.bind(("127.0.0.1", 0))
    rx.setblocking(False)
    fs = MemoryFilestore()
    fs.files["f.bin"] = bytearray(4 * SEG)
    ent = make_entity(1, [2], fs, segment=SEG, persist=False)
    udp = UdpEntity(ent, ("127.0.0.1", 0), {2: rx.getsockname()}, apid=100, rate=SEG / 2)
    try:
        ent.put(2, "f.bin", "f.bin", now=time.monotonic())
        data = 0
        end = time.monotonic() + 30.0
        while not data and time.monotonic() < end:
            udp.step(0.05)
            try:
                pdu = SpacePacket.unpack(rx.recv(70000)).data
            except BlockingIOError:
                continue
            data += bool(pdu[0] & 0x10)  # a file data PDU (not a directive)
        assert data
    finally:
        udp.close()
        rx.close()
