"""The mission folders a team starts from: `obsw mission new` writes one that passes the check
and runs; the second example (examples/aurora, every id different from the sample, its own
magnetorquer plug-in in a process of its own) passes the check and runs as far as the system
follows a mission today: ping, parameters of the plug-in, service 8 functions, its procedure."""

import fnmatch
import json
import os
import re
import signal
import socket
import subprocess
import sys
import threading
import time

import pytest
from obsw.reconfig.node import definition_dict
from obsw_host import sample
from obsw_host.mission.check import load
from obsw_host.mission.new import TEMPLATE_DIR

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
AURORA = os.path.join(ROOT, "examples", "aurora")
OBSW = [sys.executable, "-m", "obsw_host.cli"]
ENV = dict(
    os.environ,
    PYTHONPATH=os.pathsep.join([os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]),
)
ENV.pop("OBSW_MISSION", None)
BOUND = 30.0


def obsw(*args, env=ENV, cwd=None):
    return subprocess.run(OBSW + [str(a) for a in args], env=env, capture_output=True,
                          text=True, timeout=BOUND, cwd=cwd)  # fmt: skip


def free_base(apid):
    """A port base B with B + ``apid`` free (the PUS process's port)."""
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port - apid


class Obc:
    """`obsw obc serve MISSION` in its own session, its output read as it comes, stopped with
    its children at the end."""

    def __init__(self, folder, state, env):
        self.proc = subprocess.Popen(
            OBSW + ["obc", "serve", folder, "--state", str(state)], env=env,
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, start_new_session=True,
        )  # fmt: skip
        self.lines = []
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()
        self.output = None

    def _read(self):
        for line in self.proc.stdout:
            self.lines.append(line.decode(errors="replace"))

    def pids_of(self, process):
        """Every pid the OBC reported for its process ``process``, in order."""
        found = [re.search(r"OBC process '%s' \(pid (\d+)\) up" % process, x) for x in self.lines]
        return [int(m.group(1)) for m in found if m]

    def stop(self):
        if self.output is not None:
            return self.output
        try:
            os.killpg(self.proc.pid, signal.SIGTERM)
        except ProcessLookupError:  # it ended by itself
            pass
        try:
            self.proc.wait(timeout=15)
        except subprocess.TimeoutExpired:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()
        self.reader.join(5)
        self.output = "".join(self.lines)
        return self.output


def wait_for_ping(ground, obc, env=ENV):
    end = time.monotonic() + 60
    while time.monotonic() < end:
        r = obsw(*ground, "--timeout", "0.5", "ping", env=env)
        if r.returncode == 0:
            return
        assert obc.proc.poll() is None, obc.stop()
    pytest.fail("no answer to a ping within 60 s:\n" + obc.stop())


def test_the_template_node_is_the_firmware_cpdu():
    with open(os.path.join(TEMPLATE_DIR, "nodes", "cpdu.json")) as f:
        assert json.load(f) == definition_dict()
    with open(sample.CPDU_NODE_PATH) as f:
        assert json.load(f) == definition_dict()


def test_the_package_ships_the_template_and_the_schemas():
    """Every file of the template and the schemas matches the package data of pyproject.toml
    (what a `pip install` user gets for `obsw mission new` and for editors)."""
    tomllib = pytest.importorskip("tomllib")
    with open(os.path.join(ROOT, "pyproject.toml"), "rb") as f:
        patterns = tomllib.load(f)["tool"]["setuptools"]["package-data"]["obsw_host"]
    package = os.path.join(ROOT, "host", "obsw_host")
    mission = os.path.join(package, "mission")
    files = []
    for top in ("template", "schema"):
        for folder, _, names in os.walk(os.path.join(mission, top)):
            files += [os.path.relpath(os.path.join(folder, n), package) for n in names
                      if not n.endswith(".pyc")]  # fmt: skip
    assert len(files) >= 7
    assert [f for f in files if not any(fnmatch.fnmatch(f, p) for p in patterns)] == []


def test_mission_new_passes_the_check_and_runs(tmp_path):
    r = obsw("mission", "new", "pico-1", cwd=str(tmp_path))
    assert r.returncode == 0, r.stderr
    folder = tmp_path / "pico-1"
    assert sorted(os.listdir(folder)) == [
        "components", "mission.json", "nodes", "procedures", "sdb.json"]  # fmt: skip
    r = obsw("mission", "check", cwd=str(folder))  # found from the working folder
    assert r.returncode == 0, r.stderr
    assert "ok (pico-1;" in r.stdout
    m = load(str(folder))
    assert m.name == "pico-1" and m.sdb.mission == "pico-1"
    assert obsw("mission", "new", "pico-1", cwd=str(tmp_path)).returncode == 2  # not over it
    for name in ("mission.json", "sdb.json"):  # nothing of this machine in the folder
        assert str(ROOT) not in (folder / name).read_text()
    assert "cfdp" not in json.loads((folder / "mission.json").read_text())  # ports: the base's
    base = free_base(m.sdb.apid("pus"))
    env = dict(ENV, OBSW_PORT_BASE=str(base))
    obc = Obc(str(folder), tmp_path / "state", env)
    try:
        wait_for_ping(["ground", "--mission", folder], obc, env)
        r = obsw("ground", "--mission", folder, "params", "get", "pus.tc_received", env=env)
        assert r.returncode == 0, r.stderr
        # a file to this spacecraft lands in its filestore, over its own ports and entities
        (tmp_path / "up.txt").write_text("pico")
        r = obsw("cfdp", "put", "--mission", folder, "--root", tmp_path, "up.txt", "up.txt",
                 env=env)  # fmt: skip
        assert r.returncode == 0, r.stdout + r.stderr
        assert "delivered up.txt to entity %d" % m.sdb.filestores["SAT"] in r.stdout, r.stdout
        assert (tmp_path / "state" / "files" / "up.txt").read_text() == "pico"
    finally:
        out = obc.stop()
    assert "pico-1: version " in out and ", processes obc, " in out
    assert "Traceback" not in out


def test_new_missions_never_share_a_port_an_id_or_a_path_with_another(tmp_path, monkeypatch):
    """Two new missions and the examples, all on one base: no port, APID, spacecraft id or
    CFDP entity in common, and no absolute path in the files."""
    from obsw_host.mission.ids import MissionIds

    names = ["pico-1", "lynx"]
    for name in names:
        assert obsw("mission", "new", name, cwd=str(tmp_path)).returncode == 0
    r = obsw("mission", "new", "asked", "--slot", "7", cwd=str(tmp_path))
    assert r.returncode == 0 and "spacecraft id 507" in r.stdout and "pus 456" in r.stdout
    folders = [str(tmp_path / n) for n in names + ["asked"]] + [AURORA, sample.MISSION_DIR]
    monkeypatch.delenv("OBSW_PORT_BASE", raising=False)  # every mission on its own base
    seen = {}
    for folder in folders:
        ids = MissionIds.locate(folder)
        mine = {("port", ids.ports.for_apid(a)) for a in ids.sdb.apids.values() if a}
        mine |= {("port", ids.ports.cfdp_ground), ("scid", ids.sdb.scid)}
        mine |= {("entity", e) for e in ids.sdb.filestores.values()}
        for key in mine:
            assert key not in seen, "%s %s of %s is also %s's" % (key + (folder, seen.get(key)))
            seen[key] = folder
    for n in names:
        for f in ("mission.json", "sdb.json"):
            text = (tmp_path / n / f).read_text()
            assert str(tmp_path) not in text and str(ROOT) not in text


def test_aurora_differs_from_the_sample_and_passes_the_check():
    a, s = load(AURORA), load(sample.MISSION_DIR)
    assert a.name != s.name and a.sdb.mission != s.sdb.mission
    assert set(a.sdb.apids.values()).isdisjoint(s.sdb.apids.values())
    assert a.sdb.scid != s.sdb.scid  # the spacecraft id lives in the database now
    assert a.sdb.tm_vcs != s.sdb.tm_vcs
    assert set(a.sdb.filestores).isdisjoint(s.sdb.filestores)
    assert set(a.sdb.filestores.values()).isdisjoint(s.sdb.filestores.values())
    assert {n.node_id for n in a.sdb.nodes.values()}.isdisjoint(
        {n.node_id for n in s.sdb.nodes.values()})  # fmt: skip
    assert set(a.sdb.parameters).isdisjoint(s.sdb.parameters)
    types = {p.type_spec for p in a.sdb.parameters.values()}
    from obsw.pus.sdb import TYPES

    assert types == set(TYPES)  # a parameter of every type
    assert any(p.calibration and "polynomial" in p.calibration for p in a.sdb.parameters.values())
    assert any(p.calibration and "spline" in p.calibration for p in a.sdb.parameters.values())
    assert any(p.limits for p in a.sdb.parameters.values())
    assert a.config.doc["components"]["Magnetorquer"]["module"] == "components/magnetorquer.py"
    assert a.config.process_of("Magnetorquer") not in (None, a.config.process_of("pus"))
    assert os.listdir(os.path.join(AURORA, "procedures")) == ["detumble.plt"]


def wait_until(predicate, timeout=30.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        v = predicate()
        if v:
            return v
        time.sleep(0.2)
    return predicate()


def test_aurora_runs_from_its_folder(tmp_path):
    """Issue 23's check: a mission written by someone else runs from its folder alone, through
    the real CLI and nothing but ``--mission``: the OBC, its plug-in supervised, the ground,
    its procedure and CFDP (Yamcs: tests/host/test_yamcs_e2e.py)."""
    env = dict(ENV, OBSW_PORT_BASE=str(free_base(42)))  # the ground and the OBC alike

    def ground(*args):
        return obsw("ground", "--mission", AURORA, *args, env=env)

    def obcp(*args):
        return obsw("obcp", "--mission", AURORA, *args, env=env)

    obc = Obc(AURORA, tmp_path / "state", env)
    try:
        wait_for_ping(["ground", "--mission", AURORA], obc, env)
        r = ground("params", "get", "Magnetorquer.max_dipole", "adcs.gain",
                   "Magnetorquer.coil_temp", "Magnetorquer.coil_current")  # fmt: skip
        assert r.returncode == 0, r.stderr
        assert "Magnetorquer.max_dipole = 0.2 A.m^2" in r.stdout  # from the plug-in's process
        assert "adcs.gain = 250" in r.stdout
        assert re.search(r"Magnetorquer.coil_temp = [-0-9.]+ degC \(raw \d+\)", r.stdout), r.stdout
        assert "Magnetorquer.coil_current = " in r.stdout and " mA" in r.stdout

        # the mission's limit check on the calibrated coil temperature (15..35 degC, the coil
        # at about 21 degC): installed as the raw limits of those engineering values, in limits
        r = ground("monitor", "list")
        assert r.returncode == 0, r.stderr
        row = next(x for x in r.stdout.splitlines() if "Magnetorquer.coil_temp" in x)
        assert " 15 degC " in row and " 35 degC " in row, row
        r = ground("monitor", "out-of-limits")
        assert r.returncode == 0 and "(none)" in r.stdout, r.stdout
        assert ground("function", "Magnetorquer.enable").returncode == 0
        r = ground("params", "get", "Magnetorquer.enabled")
        assert "Magnetorquer.enabled = True" in r.stdout, r.stdout + r.stderr
        r = ground("function", "Magnetorquer.set_dipole", "x=0.3", "y=0", "z=0")
        assert r.returncode != 0  # the component refuses beyond max_dipole: a failure report

        # the time-driven plug-in: its mode by label, its tick detumbling the spacecraft
        r = ground("function", "Attitude.select_mode", "mode=DETUMBLE")
        assert r.returncode == 0, r.stdout + r.stderr
        r = ground("function", "Attitude.select_mode", "mode=FAST")
        assert r.returncode == 2 and "no label 'FAST'" in r.stderr, r.stdout + r.stderr
        r = wait_until(lambda: "POINTING" in ground("params", "get", "Attitude.mode").stdout)
        assert r, obc.stop()
        r = ground("params", "get", "Attitude.rate", "Attitude.ticks")
        assert re.search(r"Attitude.rate = 0\.[0-9]+ deg/s", r.stdout), r.stdout

        # a SpaceCAN node's function, its effect readable at once
        assert ground("function", "CpduA.set_state_bits", "state=5").returncode == 0
        r = ground("params", "get", "CpduA.state_bits")
        assert "CpduA.state_bits = 5" in r.stdout, r.stdout + r.stderr

        # the plug-in's process killed: the platform manager restarts it, its parameters
        # are served again by the new process
        pid = obc.pids_of("adcs")[-1]
        os.kill(pid, signal.SIGKILL)
        assert wait_until(lambda: obc.pids_of("adcs")[-1] != pid), obc.stop()
        r = wait_until(lambda: ground("params", "get", "Magnetorquer.max_dipole").stdout)
        assert "Magnetorquer.max_dipole = 0.2 A.m^2" in r, obc.stop()
        assert ground("function", "Magnetorquer.enable").returncode == 0

        # the processes with their pids, uptime and restarts, the plug-ins' among them
        def adcs_row():
            r = obsw("obc", "status", AURORA, "--state", tmp_path / "state", "--json", env=env)
            rows = [p for p in json.loads(r.stdout)["processes"] if p["name"] == "adcs"]
            return rows[0] if rows[0]["state"] == "up" and rows[0]["restarts"] == 1 else None

        row = wait_until(adcs_row)
        assert row and row["pid"] == obc.pids_of("adcs")[-1], row
        assert row["runs"] == ["Magnetorquer", "Attitude"], row
        r = obsw("obc", "status", AURORA, "--state", tmp_path / "state", env=env)
        assert re.search(r"\nadcs +%d +up +\d+ s +1 +Magnetorquer, Attitude\n" % row["pid"],
                         r.stdout), r.stdout  # fmt: skip

        # its procedure, from its own procedures folder
        r = obcp("load-ref", "detumble", ".", "detumble.plt")
        assert r.returncode == 0, r.stdout + r.stderr
        assert obcp("activate", "detumble").returncode == 0
        r = wait_until(lambda: "last outcome confirmed" in obcp("status").stdout)
        r = obcp("status")
        assert "detumble" in r.stdout and "last outcome confirmed" in r.stdout, r.stdout

        # a file up with CFDP, to the mission's filestore entity: byte-identical on board
        ground_files = tmp_path / "ground"
        ground_files.mkdir()
        data = os.urandom(20000)
        (ground_files / "up.bin").write_bytes(data)
        r = obsw("cfdp", "put", "--mission", AURORA, "--root", ground_files, "up.bin",
                 "up.bin", env=env)  # fmt: skip
        assert r.returncode == 0, r.stdout + r.stderr
        assert "delivered up.bin to entity 9" in r.stdout
        assert (tmp_path / "state" / "files" / "up.bin").read_bytes() == data
    finally:
        out = obc.stop()
    assert "CFDP entity 9" in out and "APID 42" in out
    assert "CpduA=node 20, CpduB=node 21" in out
    assert "frame processor: UART A" in out and "TM in on udp 4899" in out
    assert "event Magnetorquer.degaussed" in out
    assert "monitoring.coil_hot" not in out and "monitoring.coil_cold" not in out
    assert "event Attitude.mode_changed (info): old=OFF, new=DETUMBLE" in out
    assert "event Attitude.mode_changed (info): old=DETUMBLE, new=POINTING" in out
    assert "event Attitude.detumbled" in out
    r = obsw("obc", "status", AURORA, "--state", tmp_path / "state", env=env)
    assert r.returncode == 1 and "aurora-1: not running" in r.stdout
    assert "Traceback" not in out


def test_aurora_labels_its_function_argument_and_event_fields_in_xtce(tmp_path):
    import xml.etree.ElementTree as ET

    out = tmp_path / "aurora.xml"
    r = obsw("yamcs", "xtce", "--mission", AURORA, "-o", out)
    assert r.returncode == 0, r.stderr
    ns = {"x": "http://www.omg.org/spec/XTCE/20180204"}
    root = ET.parse(str(out)).getroot()

    def labels(kind, name):
        t = root.find(".//x:%s[@name='%s']" % (kind, name), ns)
        assert t is not None, name
        return {e.get("value"): e.get("label") for e in t.iter("{%s}Enumeration" % ns["x"])}

    modes = {"0": "OFF", "1": "DETUMBLE", "2": "POINTING"}
    assert labels("EnumeratedArgumentType", "select_mode_mode_t") == modes
    assert labels("EnumeratedParameterType", "mode_changed_new_t") == modes
