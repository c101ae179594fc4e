"""Instances that cannot collide: the state folder's lock, its default place, `obsw obc reset`,
and the platform manager's crash-loop stop (a process that cannot start is stopped with one
line and one event, never a power cycle). Every wait has a deadline."""

import argparse
import os
import subprocess
import sys

import pytest
from obsw_host.commands import obc as obc_command
from obsw_host.il.processes import python_path
from obsw_host.mission import config as obc_config
from obsw_host.obc.platform import PlatformManager
from obsw_host.obc.state import StateLock, StateLocked, default_state, reset
from obsw_host.pus.ground import Ground
from obsw_host.sample import MISSION_DIR
from test_obc_assembly import EventSink, free_port, sample, wait_for, write_config

CRASHING = """
import os

from obsw.il.interface import DATA, Attribute, Interface

BROKEN = Interface("Broken", 0x62, [Attribute("value", 1, DATA)])


class Broken:
    def __init__(self, exit_status=3):
        os._exit(exit_status)  # dies right after start, every time
"""


def mission(tmp_path, processes, components=None, tm_to=None, **platform):
    doc = sample()
    if tm_to:
        doc["pus"]["tm_to"] = tm_to
    doc["processes"] = processes
    doc["components"] = dict(doc["components"], **(components or {}))
    doc["pus"]["port"] = free_port()
    doc["cfdp"]["port"] = free_port()
    doc["platform"].update(heartbeat=0.2, deadline=1.5, **platform)
    (tmp_path / "broken.py").write_text(CRASHING)
    return write_config(tmp_path, doc)


def obc(*args, **kw):
    env = dict(os.environ, PYTHONPATH=python_path())
    cmd = [sys.executable, "-m", "obsw_host.cli", "obc", *args]
    pipe = subprocess.PIPE
    return subprocess.Popen(cmd, env=env, stdout=pipe, stderr=pipe, text=True, **kw)


def pinged(path):
    config = obc_config.load(path)
    from obsw_host.obc.topology import Topology

    topology = Topology(config)
    ground = Ground(topology.sdb, target=("127.0.0.1", topology.pus_port()), timeout=0.5)
    try:
        return ground.ping().ok
    except Exception:
        return False
    finally:
        ground.close()


def test_the_default_state_folder_is_per_mission_and_persistent(monkeypatch, tmp_path):
    monkeypatch.setenv("OBSW_STATE", str(tmp_path / "user"))
    args = argparse.Namespace(config=MISSION_DIR, state=None, il_dir=None)
    config = obc_command.load(args)
    assert config.state == os.path.join(str(tmp_path / "user"), "sample-spacecraft")
    assert config.il_directory == os.path.join(config.state, "il")
    monkeypatch.delenv("OBSW_STATE")
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "xdg"))
    assert default_state("my sat") == os.path.join(str(tmp_path / "xdg"), "obsw", "my_sat")


def test_the_lock_names_its_holder(tmp_path):
    state = str(tmp_path / "state")
    with StateLock(state):
        with pytest.raises(StateLocked) as e:
            StateLock(state).acquire()
        assert e.value.pid == os.getpid()
        assert "pid %d" % os.getpid() in str(e.value)
        with pytest.raises(StateLocked):
            reset(state)
    (tmp_path / "state" / "files").mkdir()
    assert reset(state) is True
    assert not os.path.exists(state)
    assert reset(state) is False


def test_a_second_obc_of_a_mission_refuses_and_the_first_is_untouched(tmp_path):
    path = mission(tmp_path, {"core": ["pus"]})
    first = obc("serve", path)
    try:
        assert wait_for(lambda: pinged(path) or first.poll() is not None)
        assert first.poll() is None
        second = obc("serve", path)
        out, err = second.communicate(timeout=30)
        assert second.returncode == 2
        lines = err.strip().splitlines()
        assert len(lines) == 1, err
        assert "pid %d" % first.pid in lines[0] and "in use" in lines[0]
        r = obc("reset", path)
        out, err = r.communicate(timeout=30)
        assert r.returncode == 2 and "pid %d" % first.pid in err
        assert pinged(path)  # the first still serves
    finally:
        first.terminate()
        out, err = first.communicate(timeout=30)
    for word in ("died", "restart", "power", "stopped", "already in use", "Traceback"):
        assert word not in err  # the first logged nothing about the second
    r = obc("reset", path)
    out, err = r.communicate(timeout=30)
    assert r.returncode == 0 and out.startswith("removed")
    assert not os.path.exists(tmp_path / "state")


def test_a_process_that_dies_right_after_start_is_stopped_without_power_cycle(tmp_path):
    sink = EventSink()
    path = mission(tmp_path, {"core": ["pus"], "bad": ["Broken"]}, {"Broken": {
        "module": "broken.py"}}, sink.address, crash_loop=3, max_failures=1)  # fmt: skip
    config = obc_config.load(path)
    lines = []
    pm = PlatformManager(config, out=lines.append).start()
    try:
        bad = pm.child("bad")
        assert wait_for(lambda: bad.stopped), lines
        assert wait_for(lambda: pm.child("core").last_beat is not None), lines
        db = pm.topology.sdb
        stopped = db.event("platform.stopped").id
        assert wait_for(lambda: stopped in sink.poll()), sink.events
        assert db.event("platform.power_cycle").id not in sink.events
        said = [t for _, t in pm.log if t.startswith("bad")]
        assert len([t for t in said if "stopped" in t]) == 1, said
        assert "3 times in a row before its first heartbeat" in said[-1]
        assert not pm.finished.is_set()  # the core still runs
    finally:
        pm.stop()
        sink.sock.close()
    assert pm.power_cycles == 0


def test_a_process_that_refuses_its_configuration_is_stopped_at_once(tmp_path):
    panel = {"module": "obsw_host.solar_panel", "options": {"size": 2}}  # no such argument
    path = mission(tmp_path, {"core": ["pus"], "panel": ["SolarPanel"]}, {"SolarPanel": panel})
    lines = []
    pm = PlatformManager(obc_config.load(path), out=lines.append).start()
    try:
        child = pm.child("panel")
        assert wait_for(lambda: child.stopped), lines
        assert child.restarts == 0 and "configuration" in child.stopped
    finally:
        pm.stop()
    assert pm.power_cycles == 0


def test_obsw_obc_serve_ends_when_nothing_can_run(tmp_path):
    path = mission(tmp_path, {"bad": ["Broken"]}, {"Broken": {"module": "broken.py"}})
    p = obc("serve", path)
    out, err = p.communicate(timeout=60)
    assert p.returncode == 2
    assert "every process stopped" in err.strip().splitlines()[-1]
    assert "Traceback" not in err
    assert "power-cycle" not in err


def test_a_component_module_that_does_not_import_starts_nothing(tmp_path):
    path = mission(tmp_path, {"core": ["pus", "Broken"]}, {"Broken": {"module": "nope.py"}})
    p = obc("serve", path)
    out, err = p.communicate(timeout=30)
    assert p.returncode == 2
    (line,) = err.strip().splitlines()  # the mission check's one line, before anything starts
    assert line.startswith(
        path + ": $.components.Broken.module: no file %s" % (tmp_path / "nope.py")
    )
    assert not os.path.exists(tmp_path / "state")
