"""A mission whose every id differs from the sample's: each id reaches what goes on the wire.

The mission folder below changes the APIDs, the SCID, the TC and TM virtual channels, the MAP
IDs, the CFDP entities and their prefixes, the source id and its size, the TM time code, the
node ids of the reconfiguration module, the built-in event ids and the port base. The checks
read what the tools put on the wire (a TC's header, the CFDP PDUs' space packets, the frames'
headers) and what they write for Yamcs, and run the OBC of that mission with the ground tools
pointed at it by ``--mission`` alone. No sample value may appear anywhere.
"""

import json
import os
import re
import shutil
import socket
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

import pytest
from obsw.cfdp.pdu.header import PduHeader
from obsw.frames.asm import CaduDecoder
from obsw.frames.tc import TcFrame
from obsw.frames.tm import TmFrame
from obsw.pus.config import PusConfig
from obsw.pus.tc import PusTc
from obsw.reconfig.mission import load as load_board_file
from obsw.spp import SpacePacket
from obsw.timecode import Cuc
from obsw_host import sample
from obsw_host.cli import main
from obsw_host.mission import config as obc_config
from obsw_host.mission.ids import MissionError, MissionIds
from obsw_host.obc.frames_unit import FramesUnit
from obsw_host.obc.topology import Topology
from obsw_host.obc.units import PusUnit
from obsw_host.pus.tm_fanout import SUBSCRIBE
from obsw_host.reconfig import board_file
from obsw_host.yamcs import database
from obsw_host.yamcs.obc_link import ObcLink
from obsw_host.yamcs.xtce import generate

BASE = 41000  # the mission's port base: the sample's is 5000
APIDS = {"pus": 21, "frames": 23, "cfdp": 120, "ground": 5}
SOURCE_ID = 0x33  # pus.source_id, one octet wide (the sample: apids.ground 0, two octets)
SCID = 0x155
TC_VC = 2
MAPS = {"packets": 5, "essential": 40}
TM_VCS = {"realtime": 3, "playback": 4, "essential": 5}
CFDP_VC = 1
ONBOARD = ("OBC", 9)  # filestore prefix and CFDP entity (the sample: SAT 2)
GROUND = ("MCC", 4)  # (the sample: GROUND 1)
NODES = {"MtqN": 20, "MtqR": 21}  # the sample: CpduN 10, CpduR 11
COPY_EVENTS = {"files.copy_completed": 0xA023, "files.copy_failed": 0xA024}
LAYOUT = {"source_id": SOURCE_ID, "source_id_size": 1, "time": {"coarse": 4, "fine": 3}}
NAME = "tailored-sat"

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
ENV = dict(
    os.environ,
    PYTHONPATH=os.pathsep.join([os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]),
)
ENV.pop("OBSW_PORT_BASE", None)


def tailored_sdb():
    """The sample database with every id changed (names of parameters and events kept)."""
    with open(sample.SDB_PATH) as f:
        doc = json.load(f)
    doc["mission"] = "tailored"
    doc["apids"] = dict(APIDS)
    doc["pus"] = dict(LAYOUT)
    doc["frames"] = {
        "scid": SCID,
        "tc_vc": TC_VC,
        "maps": dict(MAPS),
        "tm_vcs": dict(TM_VCS),
        "cfdp_vc": CFDP_VC,
    }
    doc["filestores"] = [
        {"prefix": ONBOARD[0], "entity": ONBOARD[1], "local": True},
        {"prefix": GROUND[0], "entity": GROUND[1]},
    ]
    roles = ["nominal", "redundant"]
    doc["nodes"] = [
        {"name": name, "node_id": nid, "definition": "node.json", "role": roles[i]}
        for i, (name, nid) in enumerate(NODES.items())
    ]
    for c in doc["components"]:  # the CPDU components take the nodes' names
        if c["name"] in ("CpduN", "CpduR"):
            c["name"] = {"CpduN": "MtqN", "CpduR": "MtqR"}[c["name"]]
    for e in doc["events"]:
        e["id"] = COPY_EVENTS.get(e["name"], e["id"])
    return doc


def write_mission(folder):
    """A mission folder: mission.json, sdb.json, the node definition and the procedures."""
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "sdb.json"), "w") as f:
        json.dump(tailored_sdb(), f, indent=1)
    shutil.copy(sample.CPDU_NODE_PATH, os.path.join(folder, "node.json"))
    with open(sample.MISSION_PATH) as f:
        doc = json.load(f)
    procedures = os.path.join(os.path.dirname(sample.MISSION_PATH), doc["obcp"]["files"])
    os.makedirs(os.path.join(folder, "procedures"))
    for name in os.listdir(procedures):  # the CPDU components are this mission's Mtq nodes
        with open(os.path.join(procedures, name)) as f:
            text = f.read().replace("CpduN", "MtqN").replace("CpduR", "MtqR")
        with open(os.path.join(folder, "procedures", name), "w") as f:
            f.write(text)
    doc["name"] = NAME
    doc["sdb"] = "sdb.json"
    doc["state"] = "state"
    doc["ports"] = {"base": BASE}
    doc["processes"] = {"obc": ["pus", "cfdp", "obcp", "SolarPanel"], "frames": ["frames"]}
    # this mission's frame processor runs without keys, and says so (secure by default)
    doc.setdefault("frames", {})["tc_security"] = "none"
    doc["pus"].pop("apid", None)  # the database's: said once
    doc["platform"]["power_cycle"]["component"] = "MtqN"
    with open(os.path.join(folder, "mission.json"), "w") as f:
        json.dump(doc, f, indent=1)
    return folder


@pytest.fixture
def mission(tmp_path, monkeypatch):
    monkeypatch.delenv("OBSW_PORT_BASE", raising=False)
    return write_mission(str(tmp_path / "tailored"))


def mission_topology(folder):
    config = obc_config.load(os.path.join(folder, "mission.json"))
    os.makedirs(config.state, exist_ok=True)
    return Topology(config)


def sample_values():
    """The sample mission's ids, none of which may show in the tailored mission's output."""
    ids = MissionIds.sample()
    return {
        "scid": ids.scid,
        "pus": ids.apid("pus"),
        "cfdp": ids.apid("cfdp"),
        "entities": ids.cfdp_entities,
        "nodes": ids.reconfig_nodes,
        "ports": ids.ports.table(),
    }


def udp(port):
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", port))
    s.settimeout(10.0)
    return s


def spawn(*argv, cwd=None):
    """``obsw ARGV`` as a process of its own."""
    return subprocess.Popen(
        [sys.executable, "-m", "obsw_host.cli"] + list(argv),
        env=ENV,
        cwd=cwd,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )


def end(proc):
    proc.terminate()
    try:
        return proc.communicate(timeout=20)[0]
    except subprocess.TimeoutExpired:
        proc.kill()
        return proc.communicate(timeout=10)[0]


# ------------------------------------------------------------------------------ the ids


def test_every_id_is_the_missions(mission):
    ids = MissionIds.locate(mission)
    assert ids.name == NAME
    assert ids.pus_apid == APIDS["pus"] and ids.apid("cfdp") == APIDS["cfdp"]
    assert ids.source_id == SOURCE_ID
    assert ids.scid == SCID and ids.tc_vc == TC_VC and ids.maps == MAPS
    assert ids.tm_vcs == TM_VCS and ids.cfdp_vc == CFDP_VC
    assert ids.cfdp_entities == (ONBOARD[1], GROUND[1])
    assert (ids.local_prefix, ids.ground_prefix) == (ONBOARD[0], GROUND[0])
    assert ids.reconfig_nodes == tuple(NODES.values())
    assert ids.event("files.copy_completed") == COPY_EVENTS["files.copy_completed"]
    assert ids.pus_config == PusConfig(source_id_size=1, time=Cuc(4, 3))
    assert ids.ports.pus == BASE + APIDS["pus"] and ids.ports.cfdp == BASE + APIDS["cfdp"]
    assert ids.ports.tm == BASE - 1 and ids.ports.yamcs_http == BASE + 3090
    theirs = sample_values()
    assert set(ids.ports.table().values()).isdisjoint(theirs["ports"].values())
    assert ids.scid != theirs["scid"] and ids.reconfig_nodes != theirs["nodes"]


def test_port_base_variable_moves_every_port(mission, monkeypatch):
    monkeypatch.setenv("OBSW_PORT_BASE", "43000")
    ports = MissionIds.locate(mission).ports
    assert ports.pus == 43000 + APIDS["pus"] and ports.cfdp_ground == 43000 + APIDS["cfdp"] + 1
    assert ports.yamcs()["pus"] == 43000 + 5015


# ------------------------------------------------------------------------------ on the wire


def test_a_ground_tc_carries_the_missions_apid_and_source_id(mission, capsys):
    onboard = udp(BASE + APIDS["pus"])  # where the mission's PUS process would listen
    try:
        status = main(["ground", "--mission", mission, "--timeout", "0.5", "ping"])
        raw = onboard.recv(65536)
    finally:
        onboard.close()
    tc = PusTc.unpack(raw, PusConfig(source_id_size=1, time=Cuc(4, 3)))
    assert (tc.apid, tc.source_id, tc.service, tc.subtype) == (APIDS["pus"], SOURCE_ID, 17, 1)
    assert status == 1
    assert "no report from 127.0.0.1:%d" % (BASE + APIDS["pus"]) in capsys.readouterr().out


def test_cfdp_pdus_carry_the_missions_entities_and_apid(mission, tmp_path):
    root = tmp_path / "ground-files"
    root.mkdir()
    (root / "f.bin").write_bytes(b"x" * 300)
    onboard = udp(BASE + APIDS["cfdp"])
    put = spawn("cfdp", "put", "--mission", mission, "--root", str(root), "f.bin")
    try:
        packet = SpacePacket.unpack(onboard.recv(65536))
    finally:
        onboard.close()
        end(put)
    assert packet.apid == APIDS["cfdp"] and packet.packet_type == 1  # a TC from the ground
    header = PduHeader.unpack(packet.data)
    assert (header.source, header.dest) == (GROUND[1], ONBOARD[1])


def test_signed_tc_frames_carry_the_missions_scid_vc_and_map(mission, tmp_path, capsys):
    keys = str(tmp_path / "tc.keys")
    vc = str(TC_VC)
    assert main(["frames", "keygen", keys, "--vcid", vc, "--essential-map", "40"]) == 0
    capsys.readouterr()
    assert main(["frames", "sign", "--mission", mission, "--keys", keys, "1d5bc0000000"]) == 0
    frame = TcFrame.unpack(bytes.fromhex(capsys.readouterr().out.strip()))
    assert (frame.scid, frame.vcid, frame.data[0] & 0x3F) == (SCID, TC_VC, MAPS["packets"])


def test_the_obc_units_use_the_missions_ids(mission):
    topology = mission_topology(mission)
    unit = PusUnit(topology, topology.process("obc"), out=lambda s: None)
    try:
        assert unit.onboard.port == BASE + APIDS["pus"] and unit.app.apid == APIDS["pus"]
        assert unit.app.config == PusConfig(source_id_size=1, time=Cuc(4, 3))
        assert unit.cfdp.apid == APIDS["cfdp"]
        assert unit.cfdp.entity.mib.entity_id == ONBOARD[1]
        assert unit.cfdp.peers == {GROUND[1]: ("127.0.0.1", BASE + APIDS["cfdp"] + 1)}
        assert unit.cfdp.address[1] == BASE + APIDS["cfdp"]
        files = unit.app.services[23]
        assert files.events == tuple(COPY_EVENTS.values()) and files.local == ONBOARD[0]
    finally:
        unit.stop()


def test_tm_frames_carry_the_missions_scid_and_vcs(mission):
    topology = mission_topology(mission)
    config = topology.config
    unit = FramesUnit(topology, topology.process("frames"), out=lambda s: None)
    with open(os.path.join(config.state, "uart_a")) as f:
        uart = os.open(f.read().strip(), os.O_RDONLY | os.O_NONBLOCK)
    sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        fp = unit.fp
        assert fp.tm_port == BASE - 1
        assert fp.routes[APIDS["pus"]] == ("127.0.0.1", BASE + APIDS["pus"])
        assert fp.default_route(0x77) == ("127.0.0.1", BASE + 0x77)
        assert fp.vc_ports == {TM_VCS["playback"]: BASE}
        pus_tm = SpacePacket(0, APIDS["pus"], b"\x20\x11\x02" + bytes(12), seq_count=1).pack()
        cfdp_tm = SpacePacket(0, APIDS["cfdp"], b"\x04" + bytes(10), seq_count=1).pack()
        sender.sendto(pus_tm, ("127.0.0.1", BASE - 1))
        sender.sendto(cfdp_tm, ("127.0.0.1", BASE - 1))
        decoder = CaduDecoder(256)
        seen = set()
        end = time.monotonic() + 10
        while time.monotonic() < end and not {TM_VCS["realtime"], CFDP_VC} <= seen:
            fp.step(0.05)
            try:
                data = os.read(uart, 65536)
            except BlockingIOError:
                continue
            for raw in decoder.feed(data):
                frame = TmFrame.unpack(raw)
                assert frame.scid == SCID
                seen.add(frame.vcid)
        assert {TM_VCS["realtime"], CFDP_VC} <= seen
    finally:
        sender.close()
        os.close(uart)
        unit.stop()


def test_the_reconfiguration_boards_get_the_missions_ids(mission, tmp_path):
    path = board_file(MissionIds.locate(mission), str(tmp_path))
    options = load_board_file(path)
    assert options == {
        "scid": SCID,
        "node_ids": tuple(NODES.values()),
        "essential_map": MAPS["essential"],
        "hptm_vc": TM_VCS["essential"],
    }


# ------------------------------------------------------------------------------ Yamcs


def test_the_yamcs_configuration_is_the_missions(mission, tmp_path, capsys):
    out = tmp_path / "yamcs"
    assert main(["yamcs", "config", str(out), "--mission", mission, "--mode", "frames"]) == 0
    assert "'%s'" % NAME in capsys.readouterr().out
    text = (out / "etc" / ("yamcs.%s.yaml" % NAME)).read_text()
    assert re.findall(r"spacecraftId: (\d+)", text) == [str(SCID)] * 2
    vcs = [int(v) for v in re.findall(r"vcId: (\d+)", text)]
    assert vcs == [TC_VC, TM_VCS["realtime"], TM_VCS["playback"], CFDP_VC, TM_VCS["essential"]]
    assert '- name: "%s"\n' % GROUND[0] in text and "id: %d" % GROUND[1] in text
    assert (
        "remoteEntities:\n" in text
        and '"%s"' % ONBOARD[0] in text
        and "id: %d" % ONBOARD[1] in text
    )
    assert "port: %d" % (BASE + 5017) in text and "port: %d" % (BASE + 5018) in text
    assert "implicitPField: 31" in text  # CUC 4+3 octets, TAI epoch
    server = (out / "etc" / "yamcs.yaml").read_text()
    assert "port: %d" % (BASE + 3090) in server and "- %s" % json.dumps(NAME) in server
    sql = (out / "etc" / "extra_streams.sql").read_text()
    assert "unhex('%04X" % (0x1000 | APIDS["cfdp"]) in sql
    mdb = ET.parse(str(out / "mdb" / "tailored.xml")).getroot()
    ns = {"x": "http://www.omg.org/spec/XTCE/20180204"}
    base = [c for c in mdb.iter("{%s}MetaCommand" % ns["x"]) if c.get("name") == "pus_tc"]
    args = {
        a.get("name"): a.get("initialValue")
        for a in base[0].iter("{%s}Argument" % ns["x"])
        if a.get("name") in ("apid", "source")
    }
    assert args == {"apid": str(APIDS["pus"]), "source": str(SOURCE_ID)}
    theirs = sample_values()
    assert "spacecraftId: %d\n" % theirs["scid"] not in text
    for port in theirs["ports"].values():
        assert "port: %d\n" % port not in text + server


def test_a_database_without_a_pus_apid_is_an_error_naming_file_and_key(mission, tmp_path):
    path = os.path.join(mission, "sdb.json")
    with open(path) as f:
        doc = json.load(f)
    del doc["apids"]["pus"]
    with open(path, "w") as f:
        json.dump(doc, f)
    with pytest.raises(MissionError, match=r"^sdb.json: apids.pus: missing"):
        generate(database.from_ids(MissionIds.locate(mission)))
    status = subprocess.run(
        [sys.executable, "-m", "obsw_host.cli", "yamcs", "config", str(tmp_path / "y")]
        + ["--mission", mission],
        env=ENV,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert status.returncode == 2
    assert status.stderr.strip().splitlines() == [
        "obsw yamcs: sdb.json: apids.pus: missing; expected the APID of the pus process (0-2047)"
    ]


def test_two_scids_are_an_error(mission):
    path = os.path.join(mission, "mission.json")
    with open(path) as f:
        doc = json.load(f)
    doc["frames"]["scid"] = 0x42
    with open(path, "w") as f:
        json.dump(doc, f)
    with pytest.raises(MissionError, match=r"mission.json: frames.scid: 66 differs"):
        _ = MissionIds.locate(mission).scid


# ------------------------------------------------------------------------------ end to end


def test_the_ground_tools_operate_the_missions_obc_by_mission_alone(mission, tmp_path):
    obc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "obsw_host.cli",
            "obc",
            "serve",
            os.path.join(mission, "mission.json"),
        ],
        env=ENV,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )

    def obsw(*argv):
        return subprocess.run(
            [sys.executable, "-m", "obsw_host.cli"] + list(argv),
            env=ENV,
            capture_output=True,
            text=True,
            timeout=90,
            cwd=str(tmp_path),
        )

    try:
        deadline = time.monotonic() + 60
        ping = None
        while time.monotonic() < deadline:
            ping = obsw("ground", "--mission", mission, "--timeout", "1", "ping")
            if ping.returncode == 0:
                break
        assert ping.returncode == 0, ping.stdout + ping.stderr
        assert ping.stdout.splitlines()[-1] == "alive", ping.stdout  # TM[17,2]
        files = tmp_path / "filestore"
        files.mkdir()
        (files / "up.bin").write_bytes(os.urandom(3000))
        put = obsw("cfdp", "put", "--mission", mission, "up.bin", "--timeout", "30")
        assert put.returncode == 0, put.stdout + put.stderr
        assert put.stdout.startswith("delivered up.bin to entity %d" % ONBOARD[1]), put.stdout
        listing = obsw("ground", "--mission", mission, "list", "files")
        assert listing.returncode == 0, listing.stdout + listing.stderr
        assert "up.bin" in listing.stdout
    finally:
        log = end(obc)
    assert "APID %d on udp 127.0.0.1:%d" % (APIDS["pus"], BASE + APIDS["pus"]) in log, log


def test_yamcs_links_to_a_running_obc_on_the_missions_ports(mission):
    ids = MissionIds.locate(mission)
    obc_pus = udp(0)
    obc_cfdp = udp(BASE + APIDS["cfdp"])
    link = ObcLink(ids, obc_pus.getsockname(), {"pus": 0, "cfdp": 0}).start()
    yamcs_pus = yamcs_cfdp = None
    try:
        assert obc_pus.recvfrom(100)[0] == SUBSCRIBE  # TM flows without a TC
        yamcs_pus = socket.create_connection(("127.0.0.1", link.ports()["pus"]), timeout=10)
        yamcs_cfdp = socket.create_connection(("127.0.0.1", link.ports()["cfdp"]), timeout=10)
        deadline = time.monotonic() + 10
        while not (link.gateway.connected("pus") and link.gateway.connected("cfdp")):
            assert time.monotonic() < deadline
            time.sleep(0.01)
        tc = SpacePacket(1, APIDS["pus"], b"\x2f\x11\x01\x33", seq_count=1).pack()
        yamcs_pus.sendall(tc)
        data, gateway = obc_pus.recvfrom(100)
        assert data == tc
        tm = SpacePacket(0, APIDS["pus"], b"\x20\x11\x02" + bytes(12), seq_count=1).pack()
        obc_pus.sendto(tm, gateway)  # the OBC answers the TC's sender
        assert yamcs_pus.recv(100) == tm
        pdu = SpacePacket(1, APIDS["cfdp"], b"\x04" + bytes(10), seq_count=2).pack()
        yamcs_cfdp.sendall(pdu)  # Yamcs' CFDP PDUs reach the OBC's entity ...
        assert obc_cfdp.recv(100) == pdu
        down = SpacePacket(0, APIDS["cfdp"], b"\x04" + bytes(10), seq_count=3).pack()
        obc_cfdp.sendto(down, ("127.0.0.1", BASE + APIDS["cfdp"] + 1))  # ... and its PDUs Yamcs
        assert yamcs_cfdp.recv(100) == down
    finally:
        for s in (yamcs_pus, yamcs_cfdp):
            if s is not None:
                s.close()
        link.close()
        obc_pus.close()
        obc_cfdp.close()


def test_problems_lists_every_missing_id_once(mission):
    assert MissionIds.locate(mission).problems() == []
    path = os.path.join(mission, "sdb.json")
    with open(path) as f:
        doc = json.load(f)
    del doc["apids"]["cfdp"]
    doc["events"] = [e for e in doc["events"] if e["name"] != "files.copy_failed"]
    doc["frames"]["maps"] = {"packets": 3, "essential": 3}
    with open(path, "w") as f:
        json.dump(doc, f)
    assert MissionIds.locate(mission).problems() == [
        "sdb.json: frames.maps: packets and essential share MAP 3",
        "sdb.json: events: no event 'files.copy_failed'; expected the built-in event's id",
        "sdb.json: apids.cfdp: missing; expected the APID of the cfdp process (0-2047)",
    ]


def test_the_board_file_carries_the_missions_recovery_thresholds(tmp_path):
    import json
    import shutil

    from obsw.reconfig.mission import parse

    folder = tmp_path / "aurora"
    shutil.copytree(os.path.join(ROOT, "examples", "aurora"), folder)
    doc = json.loads((folder / "mission.json").read_text())
    doc["recovery"] = {"deadline": 12.0, "max_failures": 2, "lines": [1, 0]}
    (folder / "mission.json").write_text(json.dumps(doc))
    written = json.loads(open(board_file(MissionIds.locate(str(folder)), str(tmp_path))).read())
    assert written["recovery"] == doc["recovery"] and written["nodes"] == [20, 21]
    parse(written)  # what a board reads, it takes
