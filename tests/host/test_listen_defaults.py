"""Onboard-facing services listen on loopback unless told otherwise (one constant says where)."""

import os
import re

from obsw_host.cli import build_parser
from obsw_host.commands import cfdp as cfdp_command
from obsw_host.frames.links import SerialLink, open_pty_pair
from obsw_host.frames.processor import FrameProcessorHost
from obsw_host.frames.station import GroundStation
from obsw_host.net import DEFAULT_HOST
from obsw_host.pus.onboard import Onboard
from obsw_host.reconfig.canhub import CanHub
from obsw_host.sample import MISSION_DIR, SDB_PATH, load_sdb
from obsw_host.solar_panel import SOLAR_PANEL, SolarPanel

HOST_TREE = os.path.join(os.path.dirname(__file__), "..", "..", "host", "obsw_host")


def test_default_is_loopback():
    assert DEFAULT_HOST == "127.0.0.1"


def test_frame_processor_binds_loopback():
    fds = []
    links = []
    for _ in range(2):
        fd, dev = open_pty_pair()
        fds.append(fd)
        links.append(SerialLink(dev))
    host = FrameProcessorHost(links[0], links[1], 0x2A, tm_port=0, vc_ports={1: 0})
    try:
        assert host.tm.getsockname()[0] == "127.0.0.1"
        assert [s.getsockname()[0] for s in host.vc_inputs] == ["127.0.0.1"]
    finally:
        host.close()
        for fd in fds:
            os.close(fd)


def test_ground_station_binds_loopback():
    station = GroundStation([], 0x2A)
    try:
        assert station.address[0] == "127.0.0.1"
    finally:
        station.close()


def test_pus_process_binds_loopback():
    panel = [(SOLAR_PANEL, SolarPanel())]  # hosted here: no wait for a remote component
    onboard = Onboard(load_sdb(SDB_PATH), port=0, period=0.05, components=panel).start()
    try:
        assert onboard.address[0] == "127.0.0.1"
    finally:
        onboard.stop()


def test_cfdp_entity_binds_loopback(tmp_path):
    args = build_parser().parse_args(
        ["cfdp", "serve", "--port", "0", "--root", str(tmp_path / "fs")]
    )
    assert args.host == DEFAULT_HOST
    udp, _ = cfdp_command._setup(args, onboard=True)
    try:
        assert udp.address[0] == "127.0.0.1"
    finally:
        udp.close()


def test_can_hub_binds_loopback():
    hub = CanHub()
    try:
        assert all(s.getsockname()[0] == "127.0.0.1" for s in hub.socks)
    finally:
        hub.close()


def test_commands_default_to_loopback():
    parser = build_parser()
    from obsw_host.mission.config import load

    assert load(MISSION_DIR).host == DEFAULT_HOST  # the sample binds loopback: it names none
    args = parser.parse_args(["frames", "processor", "--uart-a", "a", "--uart-b", "b"])
    assert args.host == DEFAULT_HOST


def test_no_module_binds_every_interface_or_spells_the_address():
    """No host module binds every interface (0.0.0.0 or the empty address)."""
    every = re.compile(r"0\.0\.0\.0|bind\(\(\s*['\"]{2}")
    for folder, _, files in os.walk(HOST_TREE):
        for name in files:
            if not name.endswith(".py"):
                continue
            path = os.path.join(folder, name)
            with open(path) as f:
                text = f.read()
            assert not every.search(text), path
