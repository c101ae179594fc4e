"""One way from an APID to its port: a mission that fixes the ``pus`` and ``cfdp`` ports by
name gets its TCs there, through the frames (ground FOP-1, CLTUs, the OBC's frame unit)."""

import json
import os
import shutil
import socket
import time

import pytest
from obsw.frames import fop as F
from obsw_host import sample
from obsw_host.frames.ground import Ground
from obsw_host.frames.links import SerialLink
from obsw_host.mission import config as mission_config
from obsw_host.mission.ids import MissionIds
from obsw_host.mission.ports import Ports
from obsw_host.obc.frames_unit import FramesUnit
from obsw_host.obc.topology import Topology


def _bound(n):
    socks = []
    for _ in range(n):
        s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        s.bind(("127.0.0.1", 0))
        s.setblocking(False)
        socks.append(s)
    return socks


def _free_base():
    """A base whose whole mission range (base - 1 .. base + 5100) is below 65536 and whose
    TM port is free now."""
    while True:
        s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
        s.close()
        if port + 6000 < 65536:
            return port + 1


def test_for_apid_follows_ports_fixed_by_name(monkeypatch):
    monkeypatch.delenv("OBSW_PORT_BASE", raising=False)  # it would move the base given here
    ports = Ports(6000, {"pus": 10, "cfdp": 100, "frames": 12}, {"pus": 7001, "cfdp": 7002})
    assert ports.for_apid(10) == 7001 and ports.for_apid(100) == 7002
    assert ports.for_apid(12) == 6012 and ports.for_apid(11) == 6011
    assert ports.cfdp_ground == 6101  # still base + cfdp APID + 1: only "cfdp" was fixed
    assert ports.routes("h") == {10: ("h", 7001), 12: ("h", 6012), 100: ("h", 7002)}


@pytest.fixture
def mission(tmp_path, monkeypatch):
    monkeypatch.delenv("OBSW_PORT_BASE", raising=False)
    folder = str(tmp_path / "fixed")
    shutil.copytree(sample.MISSION_DIR, folder)
    pus, cfdp = _bound(2)
    path = os.path.join(folder, "mission.json")
    with open(path) as f:
        doc = json.load(f)
    doc["ports"] = {
        "base": _free_base(),
        "pus": pus.getsockname()[1],
        "cfdp": cfdp.getsockname()[1],
    }
    doc["processes"]["frames"] = ["frames"]
    doc["frames"]["tc_security"] = "none"
    with open(path, "w") as f:
        json.dump(doc, f)
    yield path, pus, cfdp
    pus.close()
    cfdp.close()


def _tc(apid, seq, payload):
    n = len(payload)
    return bytes((0x18 | apid >> 8, apid & 0xFF, 0xC0, seq, 0, n - 1)) + payload


def test_tcs_reach_the_ports_fixed_by_name(mission):
    path, pus, cfdp = mission
    config = mission_config.load(path)
    os.makedirs(config.state, exist_ok=True)
    topology = Topology(config)
    ids = MissionIds.locate(path)
    unit = FramesUnit(topology, topology.process("frames"), out=lambda s: None)
    assert unit.fp.routes[ids.apid("pus")] == ("127.0.0.1", pus.getsockname()[1])
    links = []
    for side in ("a", "b"):
        with open(os.path.join(config.state, "uart_" + side)) as f:
            links.append(SerialLink(f.read().strip()))
    length = int(config.section("frames").get("tm_frame_length", 256))
    ground = Ground(links, ids.scid, tm_frame_length=length)
    unit.start()
    try:
        t0 = time.monotonic()
        ground.initiate(0.0)
        sent = {pus: _tc(ids.apid("pus"), 1, b"to pus"), cfdp: _tc(ids.apid("cfdp"), 2, b"cfdp")}
        got = {}
        end = t0 + 20
        queued = False
        while time.monotonic() < end and len(got) < 2:
            now = time.monotonic() - t0
            ground.poll(now, 0.02)
            if ground.fop.state == F.ACTIVE and not queued:
                for packet in sent.values():
                    ground.send(packet, now)
                queued = True
            for s in sent:
                try:
                    got[s] = s.recv(4096)
                except BlockingIOError:
                    pass
        assert got == sent
        assert unit.fp.unrouted == 0
    finally:
        unit.stop()
        for link in links:
            link.close()


def _write(path, edit):
    with open(path) as f:
        doc = json.load(f)
    edit(doc)
    with open(path, "w") as f:
        json.dump(doc, f)


def test_both_ends_code_as_the_mission_says(mission):
    """The OBC's frame unit encodes with the mission's tm_coding, at its downlink rate; the
    station built from the same mission decodes it, and TCs still go up through it."""
    from obsw_host.frames.station import GroundStation

    path, pus, _ = mission

    def coded(doc):
        doc["frames"]["tm_coding"] = {"scheme": "concatenated", "interleave": 2}
        doc["frames"]["downlink_bps"] = 400000  # a fast radio: the test takes no longer

    _write(path, coded)
    config = mission_config.load(path)
    os.makedirs(config.state, exist_ok=True)
    topology = Topology(config)
    ids = MissionIds.locate(path)
    unit = FramesUnit(topology, topology.process("frames"), out=lambda s: None)
    assert unit.fp.core.tm_coding.coding == "concatenated"
    links = []
    for side in ("a", "b"):
        with open(os.path.join(config.state, "uart_" + side)) as f:
            links.append(SerialLink(f.read().strip()))
    station = GroundStation.for_mission(ids, links)
    mcs = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    mcs.bind(("127.0.0.1", 0))
    unit.start()
    try:
        tm = bytes((0x08 | ids.apid("pus") >> 8, ids.apid("pus") & 0xFF, 0xC0, 1, 0, 3)) + b"abcd"
        tc = _tc(ids.apid("pus"), 3, b"up")
        mcs.sendto(tc, station.address)  # the station learns where TM goes
        got_tc = None
        end = time.monotonic() + 30
        while time.monotonic() < end:
            station.step(0.02)
            try:
                got_tc = pus.recv(4096)
                pus.sendto(tm, ("127.0.0.1", unit.fp.tm_port))  # answer: TM down
            except BlockingIOError:
                pass
            if tm in [p for _, p in station.downlinked]:
                break
        assert got_tc == tc
        assert tm in [p for _, p in station.downlinked]
        coding = station.ground.coding()
        assert coding["frames"] > 0 and coding["uncorrectable"] == 0 and coding["locks"] >= 1
    finally:
        unit.stop()
        station.close()
        mcs.close()


def test_mission_check_names_a_coding_that_does_not_fit(mission, capsys):
    from obsw_host.cli import main

    path = mission[0]
    _write(path, lambda d: d["frames"].update(tm_coding={"scheme": "rs", "rs_e": 8}))
    assert main(["mission", "check", path]) != 0
    err = capsys.readouterr()
    line = (err.out + err.err).strip()
    assert line == (
        "%s: $.frames.tm_coding.interleave: 256-octet TM frames do not fit RS(255,239) "
        "interleaved 1 (239 octets at most); expected interleave 2 or a shorter "
        "tm_frame_length" % path
    )
    _write(path, lambda d: d["frames"]["tm_coding"].update(interleave=2))
    assert main(["mission", "check", path]) == 0


def test_the_obcs_uart_through_the_simulated_radio(mission):
    """The OBC's frame unit on its pty, the radio model on the other end of it (bit errors at
    1e-3 on AWGN-free hard bits, the mission's rates), the station on the radio's UDP side:
    a TC goes up through COP-1 and its answer comes down decoded."""
    from obsw_host.frames.coding import LinkSettings
    from obsw_host.frames.radio import UdpLink
    from obsw_host.frames.station import GroundStation
    from obsw_sim.radio import RadioLink

    path, pus, _ = mission

    def radio(doc):
        doc["frames"].update(
            tm_coding={"scheme": "concatenated", "interleave": 2},
            downlink_bps=64000, uplink_bps=9600, radio={"ber": 1e-3, "seed": 5},
        )  # fmt: skip

    _write(path, radio)
    config = mission_config.load(path)
    os.makedirs(config.state, exist_ok=True)
    topology = Topology(config)
    ids = MissionIds.locate(path)
    unit = FramesUnit(topology, topology.process("frames"), out=lambda s: None)
    with open(os.path.join(config.state, "uart_a")) as f:
        uart = os.open(f.read().strip(), os.O_RDWR | os.O_NOCTTY)
    station_link = UdpLink(0, "octets")
    station = GroundStation.for_mission(ids, [station_link])
    air = RadioLink.from_mission(LinkSettings.of(config), uart, station_link.address)
    station_link.peer = air.address
    mcs = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    mcs.bind(("127.0.0.1", 0))
    unit.start()
    air.start()
    try:
        tm = bytes((0x08 | ids.apid("pus") >> 8, ids.apid("pus") & 0xFF, 0xC0, 9, 0, 3)) + b"down"
        tc = _tc(ids.apid("pus"), 4, b"over the air")
        mcs.sendto(tc, station.address)
        got_tc = None
        end = time.monotonic() + 60
        while time.monotonic() < end and tm not in [p for _, p in station.downlinked]:
            station.step(0.02)
            try:
                got_tc = pus.recv(4096)
                pus.sendto(tm, ("127.0.0.1", unit.fp.tm_port))
            except BlockingIOError:
                pass
        assert got_tc == tc
        assert tm in [p for _, p in station.downlinked]
        coding = station.coding()
        assert air.down.flipped > 0 and coding["symbol_errors"] > 0
        assert coding["uncorrectable"] == 0 and coding["losses"] == 0
    finally:
        air.stop()
        unit.stop()
        station.close()
        mcs.close()
        os.close(uart)
