"""TC security through the real frame processor on two pty UARTs: signed frames go through;
forged, replayed and unsigned ones are each rejected with a service 5 event to ground."""

import socket
import struct
import threading
import time

import pytest
from obsw.frames import fop as F
from obsw.frames import sdls
from obsw.frames.cltu import encode
from obsw.frames.tc import Segment, TcFrame
from obsw.pus import sdb as sdb_module
from obsw.pus.tm import PusTm
from obsw_host.frames import keys
from obsw_host.frames.ground import Ground
from obsw_host.frames.links import FdLink, SerialLink, open_pty_pair
from obsw_host.frames.processor import FrameProcessorHost, sdb_events, security_options
from obsw_host.net import DEFAULT_HOST
from obsw_host.sample import SDB_PATH

SCID = 0x33
APID = 0x40
LENGTH = 96


def tc_packet(seq, payload):
    n = len(payload)
    return bytes((0x18, APID, 0xC0 | seq >> 8, seq & 0xFF, 0, n - 1)) + payload


@pytest.fixture(params=["hmac-sha256", "aes-gcm"])
def rig(tmp_path, request):
    key_file = str(tmp_path / "tc.keys")
    gcm = request.param != "hmac-sha256"
    keys.generate(key_file, algorithm=request.param, tm_vcids=(0, 1) if gcm else ())
    db = sdb_module.load(SDB_PATH)
    secured = security_options(key_file, db, str(tmp_path / "onboard.state"))
    ground_security, ground_tm, ground_state = keys.load_all(
        key_file, str(tmp_path / "ground.state")
    )
    event_apid, event_ids = sdb_events(db)
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
        **secured,
    )
    stop = threading.Event()
    worker = threading.Thread(target=obc.run, args=(stop,), daemon=True)
    worker.start()
    ground = Ground(
        [FdLink(ctrl_a), FdLink(ctrl_b)],
        SCID,
        tm_frame_length=LENGTH,
        t1=1.0,
        security=ground_security,
        state=ground_state,
        tm_security=ground_tm,
    )
    t0 = time.monotonic()
    received = []

    def pump(until, limit=10.0):
        end = time.monotonic() + limit
        while time.monotonic() < end:
            ground.poll(time.monotonic() - t0, 0.01)
            try:
                while True:
                    received.append(app.recv(65536))
            except BlockingIOError:
                pass
            if until():
                return True
        return False

    def events():
        out = []
        for p in ground.packets:
            tm = PusTm.unpack(p)
            if tm.service == 5:
                vcid, spi, sn = struct.unpack(">BHQ", tm.data[2:])
                out.append((tm.subtype, (tm.data[0] << 8) | tm.data[1], vcid, spi, sn))
        return out

    class Rig:
        pass

    r = Rig()
    r.obc, r.ground, r.pump, r.received, r.events = obc, ground, pump, received, events
    r.ids, r.event_apid, r.tmp = event_ids, event_apid, tmp_path
    r.tm_security, r.ground_tm = secured["tm_security"], ground_tm
    r.now = lambda: time.monotonic() - t0
    yield r
    stop.set()
    worker.join(2)
    obc.close()
    for link in ground.links:
        link.close()
    app.close()


def test_signed_accepted_forged_replayed_unsigned_rejected_with_events(rig):
    rig.ground.initiate(rig.now())
    assert rig.pump(lambda: rig.ground.fop.state == F.ACTIVE)
    signed = tc_packet(1, b"signed")
    rig.ground.send(signed, rig.now())
    assert rig.pump(lambda: rig.received and rig.ground.idle)
    assert rig.received == [signed]
    good = rig.ground.sent_frames[-1].pack()
    link_a = rig.ground.links[0]

    forged = bytearray(TcFrame.unpack(good).data)
    forged[10] ^= 0x04  # inside the packet; the FECF of the re-made frame is good
    link_a.write(encode(TcFrame(SCID, 0, bytes(forged), 0, True).pack()))
    assert rig.pump(lambda: len(rig.events()) == 1)

    link_a.write(encode(good))  # the very same frame again, on one link
    assert rig.pump(lambda: len(rig.events()) == 2)

    plain = Segment(1, tc_packet(2, b"unsigned")).pack()
    link_a.write(encode(TcFrame(SCID, 0, plain, 0, True).pack()))
    assert rig.pump(lambda: len(rig.events()) == 3)

    spi = rig.ground.security.sa_for(0, 1).spi
    assert rig.events() == [
        (3, rig.ids[sdls.BAD_MAC], 0, spi, 0),
        (3, rig.ids[sdls.REPLAY], 0, spi, 1),
        (3, rig.ids[sdls.BAD_SPI], 0, (plain[1] << 8) | plain[2], 0),
    ]
    assert rig.received == [signed]  # nothing but the signed command reached the application
    c = rig.obc.core.security.counters
    assert (c["ok"], c["bad_mac"], c["replay"], c["bad_spi"]) == (1, 1, 1, 1)
    assert rig.obc.core.counters["tc_rejected"] == 3

    # the sequence numbers outlive the process: a restarted receiver still refuses the replay
    fresh, _ = keys.load(str(rig.tmp / "tc.keys"), str(rig.tmp / "onboard.state"))
    sa = fresh.sas[spi]
    assert not sa.window.acceptable(1) and sa.window.acceptable(2)
    again, _ = keys.load(str(rig.tmp / "tc.keys"), str(rig.tmp / "ground.state"))
    # HMAC: the number saved after each frame; GCM: the end of the reserved IV block, so that
    # a restarted sender never uses an IV twice
    assert again.sas[spi].sn_sent == (1 if rig.ground_tm is None else 64)
    if rig.ground_tm is not None:  # the events came down in encrypted TM frames
        assert rig.ground_tm.counters["ok"] > 0 and rig.ground_tm.counters["bad_mac"] == 0


def test_events_can_be_disabled_by_tc_to_the_frame_processor(rig):
    from obsw.pus.tc import PusTc

    rig.ground.initiate(rig.now())
    assert rig.pump(lambda: rig.ground.fop.state == F.ACTIVE)
    bad_spi = rig.ids[sdls.BAD_SPI]
    disable = PusTc(rig.event_apid, 5, 6, bytes((1, bad_spi >> 8, bad_spi & 0xFF)), 0, ack=0)
    rig.ground.send(disable.pack(), rig.now())
    reports = rig.obc.pus.services[5]
    assert rig.pump(lambda: bad_spi in reports.disabled and rig.ground.idle)
    link_a = rig.ground.links[0]
    link_a.write(encode(TcFrame(SCID, 0, Segment(1, b"\x00" * 12).pack(), 0, True).pack()))
    assert rig.pump(lambda: reports.suppressed == 1)
    assert rig.events() == []
    assert rig.obc.core.security.counters["bad_spi"] == 1


def test_key_files(tmp_path):
    path = str(tmp_path / "k.json")
    sas = keys.generate(path, vcids=(0, 1))
    assert [(s.spi, s.vcid, s.map_id) for s in sas] == [(1, 0, None), (2, 1, None), (63, 0, 63)]
    with pytest.raises(FileExistsError):
        keys.generate(path)
    security, _ = keys.load(path)
    assert security.sas[63].key == sas[2].key
    import os

    os.chmod(path, 0o644)
    with pytest.raises(sdls.SdlsError):
        keys.load(path)
    with pytest.raises(sdls.SdlsError):  # never into a repository
        keys.generate(os.path.join(os.path.dirname(__file__), "x.keys"))


def test_station_signs_and_refuses_without_operational_sa(tmp_path):
    from obsw_host.frames.station import GroundStation

    path = str(tmp_path / "k.keys")
    keys.generate(path)
    security, state = keys.load(path)
    station = GroundStation([], SCID, security=security, state=state)
    mcs = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        mcs.sendto(tc_packet(1, b"one"), station.address)
        station.step(0)
        security.sas[1].stop()
        mcs.sendto(tc_packet(2, b"two"), station.address)
        station.step(0)
        assert (station.uplinked, station.refused) == (1, 1)
        assert security.sas[1].sn_sent == 1
    finally:
        mcs.close()
        station.close()


def test_sample_database_names_the_core_event_ids():
    db = sdb_module.load(SDB_PATH)
    apid, ids = sdb_events(db)
    assert ids == sdls.EVENT_IDS
    assert apid == db.apid("frames")
    assert {db.event(i).severity for i in ids[1:]} == {3}  # medium: TM[5,3]


def test_station_sends_the_operators_tcs_before_a_files_pdus():
    from obsw_host.frames.station import GroundStation

    files = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    files.bind(("127.0.0.1", 0))
    mcs = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    station = GroundStation([], SCID, routes={0x7F0: files.getsockname()})
    try:
        for i in range(3):
            files.sendto(tc_packet(i, b"file data"), station.address)
        mcs.sendto(tc_packet(9, b"operator"), station.address)
        station.step(0)  # on the loopback a datagram is in the socket when sendto returns
        # no links here: FOP-1 holds what it was given, so COP-1's queue stays as it was left
        queue = station.ground.queue
        assert len(queue) == 1 and queue[0].endswith(b"operator")  # the TC went first
        assert len(station.routed) == 3 and station.uplinked == 1
        queue.clear()  # as if FOP-1 had sent it: the next file PDU goes, one at a time
        station.step(0)
        assert len(queue) == 1 and queue[0].endswith(b"file data")
        assert len(station.routed) == 2 and station.uplinked == 2
    finally:
        files.close()
        mcs.close()
        station.close()
