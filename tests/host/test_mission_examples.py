"""The mission folders a team starts from: `obsw mission new` writes one that passes the check
and runs; the second example (examples/aurora, every id different from the sample, its own
magnetorquer plug-in in a process of its own) passes the check and runs as far as the system
follows a mission today: ping, parameters of the plug-in, service 8 functions, its procedure."""

import fnmatch
import json
import os
import signal
import socket
import subprocess
import sys
import time

import pytest
from obsw.reconfig.node import definition_dict
from obsw_host import sample
from obsw_host.mission import load
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
    """`obsw obc serve MISSION` in its own session, stopped with its children at the end."""

    def __init__(self, folder, state, env):
        self.proc = subprocess.Popen(
            OBSW + ["obc", "serve", folder, "--state", str(state)], env=env,
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, start_new_session=True,
        )  # fmt: skip
        self.output = None

    def stop(self):
        if self.output is not None:
            return self.output
        try:
            os.killpg(self.proc.pid, signal.SIGTERM)
        except ProcessLookupError:  # it ended by itself
            pass
        try:
            out, _ = self.proc.communicate(timeout=15)
        except subprocess.TimeoutExpired:
            os.killpg(self.proc.pid, signal.SIGKILL)
            out, _ = self.proc.communicate()
        self.output = out.decode(errors="replace")
        return self.output


def wait_for_ping(ground, obc):
    end = time.monotonic() + 60
    while time.monotonic() < end:
        r = obsw(*ground, "--timeout", "0.5", "ping")
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
    base = free_base(10)
    env = dict(ENV, OBSW_PORT_BASE=str(base))
    obc = Obc(str(folder), tmp_path / "state", env)
    try:
        wait_for_ping(["ground", "--mission", folder, "--port", base + 10], obc)
        r = obsw("ground", "--sdb", folder / "sdb.json", "--port", base + 10, "params", "get",
                 "pus.tc_received")  # fmt: skip
        assert r.returncode == 0, r.stderr
    finally:
        out = obc.stop()
    assert "pico-1: processes obc" in out
    assert "Traceback" not in out


def test_aurora_differs_from_the_sample_and_passes_the_check():
    a, s = load(AURORA), load(sample.MISSION_DIR)
    assert a.name != s.name and a.sdb.mission != s.sdb.mission
    assert set(a.sdb.apids.values()).isdisjoint(s.sdb.apids.values())
    assert a.sdb.scid != s.sdb.scid
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


def test_aurora_runs_from_its_folder(tmp_path):
    """As far as the system follows the mission today (see docs/fly-your-own-spacecraft.md)."""
    base = free_base(42)
    env = dict(ENV, OBSW_PORT_BASE=str(base))
    ground = ["--sdb", os.path.join(AURORA, "sdb.json"), "--apid", 42, "--port", base + 42]
    obc = Obc(AURORA, tmp_path / "state", env)
    try:
        wait_for_ping(["ground"] + ground, obc)
        r = obsw("ground", *ground, "params", "get", "Magnetorquer.max_dipole", "adcs.gain")
        assert r.returncode == 0, r.stderr
        assert "Magnetorquer.max_dipole = 0.2" in r.stdout  # from the plug-in's own process
        assert "adcs.gain = 250" in r.stdout
        assert obsw("ground", *ground, "function", "Magnetorquer.enable").returncode == 0
        r = obsw("ground", *ground, "params", "get", "Magnetorquer.enabled")
        assert "Magnetorquer.enabled = True" in r.stdout, r.stdout + r.stderr
        r = obsw("ground", *ground, "function", "Magnetorquer.set_dipole", "x=0.3", "y=0", "z=0")
        assert r.returncode != 0  # the component refuses beyond max_dipole: a failure report
        r = obsw("obcp", *ground, "load-ref", "detumble", ".", "detumble.plt")
        assert r.returncode == 0, r.stdout + r.stderr
        assert obsw("obcp", *ground, "activate", "detumble").returncode == 0
        end = time.monotonic() + 20
        while time.monotonic() < end:
            r = obsw("obcp", *ground, "status")
            if "last outcome confirmed" in r.stdout:
                break
            time.sleep(0.3)
        assert "detumble" in r.stdout and "last outcome confirmed" in r.stdout, r.stdout
    finally:
        out = obc.stop()
    assert "CFDP entity 9" in out and "APID 42" in out
    assert "CpduA=node 20, CpduB=node 21" in out
    assert "frame processor: UART A" in out and "TM in on udp 4899" in out
    assert "event Magnetorquer.degaussed" in out
    assert "Traceback" not in out
