"""The OBCP engine and the solar panel in separate processes: procedures loaded, run and
controlled through a proxy, their progress seen as events. Waits are bounded by deadlines."""

import os
import subprocess
import sys
import time

import pytest
from obcp_engine_demo import DEMO_PROCEDURE, demo
from obsw.il.errors import ComponentError
from obsw.il.node import Node
from obsw.pluto.obcp import ENGINE
from obsw_host.il.directory import Directory
from obsw_host.il.processes import python_path, spawn, stop
from obsw_host.il.transport import SocketTransport
from obsw_host.solar_panel import SOLAR_PANEL

pytestmark = pytest.mark.skipif(not hasattr(os, "fork"), reason="needs Unix processes")


@pytest.fixture
def directory(tmp_path):
    return str(tmp_path)


@pytest.fixture
def procs(directory):
    started = [spawn("obsw_host.solar_panel", directory), spawn("obsw_host.obcp", directory)]
    yield started
    for p in started:
        stop(p)


@pytest.fixture
def user(directory):
    node = Node("test-operator")
    transport = SocketTransport(node, directory, listen=False)
    yield node
    transport.close()


def until_finished(events, names, timeout=20.0):
    """Events until every OBCP in ``names`` has finished (or the deadline)."""
    got = []
    left = set(names)
    deadline = time.monotonic() + timeout
    while left and time.monotonic() < deadline:
        pub = events.receive(timeout=0.5)
        if not pub or pub.member in ("obcps", "states"):
            continue
        got.append((pub.member, pub.value))
        if pub.member == "finished":
            left.discard(pub.value["obcp"])
    assert not left, "not finished within %ss: %s" % (timeout, sorted(left))
    return got


def test_procedure_drives_panel_across_processes(procs, user):
    engine = user.proxy(ENGINE, timeout=20.0)
    events = engine.subscribe("*", length=128)
    engine.load("turn", DEMO_PROCEDURE)
    assert engine.states == {"turn": "inactive"}
    engine.activate("turn", None)
    got = until_finished(events, ["turn"])
    logs = [v["text"] for m, v in got if m == "log"]
    assert logs == ["angle before: 0.0 deg", "angle after: 30.0 deg"]
    steps = [(v["step"], v["status"]) for m, v in got if m == "step_status"]
    assert steps == [
        ("Deploy", "executing"),
        ("Deploy", "confirmed"),
        ("Turn", "executing"),
        ("Turn", "confirmed"),
    ]
    assert [v for m, v in got if m == "finished"] == [
        {"obcp": "turn", "outcome": "confirmed", "error": None}
    ]
    panel = user.proxy(SOLAR_PANEL, timeout=20.0)
    assert (panel.angle, panel.is_deployed) == (30.0, True)
    status = engine.status("turn")
    assert status["steps"] == {"Deploy": "confirmed", "Turn": "confirmed"}


def test_refusals_cross_the_process_boundary(procs, user):
    engine = user.proxy(ENGINE, timeout=20.0)
    with pytest.raises(ComponentError) as e:
        engine.load("bad", "procedure main\n  log tilt of SolarPanel;\nend main end procedure")
    assert e.value.code == "LOAD_FAILED"
    assert e.value.data["kind"] == "unknown_reference"
    assert e.value.data["line"] == 2
    with pytest.raises(ComponentError) as e:
        engine.activate("nothing", None)
    assert e.value.code == "UNKNOWN_OBCP"


def test_two_procedures_controlled_remotely(procs, user):
    engine = user.proxy(ENGINE, timeout=20.0)
    events = engine.subscribe("*", length=256)
    waiting = (
        "procedure main initiate and confirm step Hold main wait for 10 min; end main end step;"
        " end main end procedure"
    )
    turning = (
        "procedure main initiate and confirm step T main"
        " initiate and confirm deploy of SolarPanel;"
        " initiate and confirm set_angle of SolarPanel with arguments angle := -20 deg end with;"
        ' log "at ", angle of SolarPanel; end main end step; end main end procedure'
    )
    engine.load("hold", waiting)
    engine.load("turn", turning)
    engine.activate("hold", None)
    engine.suspend("hold")  # takes effect at its next statement boundary: after the wait
    assert engine.status("hold")["requested"] == "suspend"
    engine.resume("hold")
    engine.activate("turn", None)
    got = until_finished(events, ["turn"])
    assert [v["text"] for m, v in got if m == "log"] == ["at -20.0 deg"]
    assert engine.states == {"hold": "running", "turn": "inactive"}
    engine.abort("hold")
    got = until_finished(events, ["hold"])
    assert [v for m, v in got if m == "finished"][0]["error"] == "aborted by request"
    assert engine.states == {"hold": "inactive", "turn": "inactive"}


def test_engine_subcommand_stops_cleanly(directory, user):
    env = dict(os.environ, PYTHONPATH=python_path(), OBSW_IL_DIR=directory)
    proc = subprocess.Popen(
        [sys.executable, "-m", "obsw_host.cli", "pluto", "engine", "--dir", directory, "--quiet"],
        env=env,
        stdin=subprocess.DEVNULL,
    )
    try:
        engine = user.proxy(ENGINE, timeout=20.0)
        assert engine.obcps == []
    finally:
        assert stop(proc) == 0
    assert Directory(directory).read("ObcpEngine") is None


def test_demo_prints_progress(directory):
    lines = []
    assert demo(out=lines.append, directory=directory) == 0
    text = "\n".join(lines)
    assert "  log           angle before: 0.0 deg" in lines
    assert "  log           angle after: 30.0 deg" in lines
    assert "  step Turn     confirmed" in lines
    assert "  finished      confirmed" in lines
    assert "SolarPanel    angle 30.0 deg, deployed True" in text
    assert lines[-1] == "  engine and panel processes stopped"
