"""The operator's ground through the real `obsw` command: TM to every client, the live monitor,
session logs and replay, discovery, readable replies and the on-board process's log."""

import json
import os
import queue
import signal
import socket
import subprocess
import sys
import threading

import pytest
from obsw_host.sample import SDB_PATH

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
OBSW = [sys.executable, "-m", "obsw_host.cli"]
ENV = dict(
    os.environ,
    PYTHONPATH=os.pathsep.join([os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]),
    PYTHONUNBUFFERED="1",
)
BOUND = 30  # seconds any one process of these tests may take, at most


def free_base():
    """A port base B with B + 10 (the PUS process, APID 10) free."""
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port - 10


def obsw(*args, cwd=None):
    return subprocess.run(
        OBSW + [str(a) for a in args],
        env=ENV,
        capture_output=True,
        text=True,
        timeout=BOUND,
        cwd=cwd,
    )


class Lines:
    """The lines streams of a running process write, read by threads into one queue."""

    def __init__(self, *streams):
        self.queue = queue.Queue()
        self.seen = []
        self.open = len(streams)
        for stream in streams:
            threading.Thread(target=self._read, args=(stream,), daemon=True).start()

    @classmethod
    def merged(cls, *lines):
        out = cls()
        out.open = len(lines)
        for x in lines:
            threading.Thread(target=out._forward, args=(x,), daemon=True).start()
        return out

    def _forward(self, lines):
        while True:
            line = lines.queue.get()
            if line is None:
                break
            self.queue.put(line)
        self.queue.put(None)

    def _read(self, stream):
        for line in stream:
            self.queue.put(line.rstrip("\n"))
        self.queue.put(None)

    def until(self, predicate):
        """Lines up to the first for which ``predicate`` holds (AssertionError at the end)."""
        while True:
            line = self.queue.get(timeout=BOUND)
            if line is None:
                self.open -= 1
                if self.open > 0:
                    continue
                raise AssertionError("stream ended; lines: %s" % self.seen[-20:])
            self.seen.append(line)
            if predicate(line):
                return line


def start(*args, env=None):
    proc = subprocess.Popen(
        OBSW + [str(a) for a in args],
        env=env or ENV,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    return proc, Lines(proc.stdout), Lines(proc.stderr)


def stop(proc):
    os.killpg(proc.pid, signal.SIGTERM)
    try:
        proc.wait(BOUND)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()


@pytest.fixture
def obc(tmp_path):
    """`obsw obc serve` of a mission with the PUS process and the solar panel only."""
    base = free_base()
    mission = tmp_path / "mission.json"
    mission.write_text(
        json.dumps(
            {
                "format": 2,
                "name": "test-ground",
                "sdb": SDB_PATH,
                "state": "state",
                "processes": {"obc": ["pus", "SolarPanel"]},
                "components": {"SolarPanel": {"module": "obsw_host.solar_panel"}},
                "pus": {"apid": 10, "period": 0.1},
            }
        )
    )
    env = dict(ENV, OBSW_PORT_BASE=str(base))
    proc, out, err = start("obc", "serve", mission, env=env)
    both = Lines.merged(out, err)
    both.until(lambda line: " up: " in line)
    before = ENV.get("OBSW_MISSION")
    ENV["OBSW_MISSION"] = str(mission)  # the ground commands of the test use this mission
    try:
        yield base + 10, both
    finally:
        # as it was: the tests after it in this process use the sample (tests/conftest.py)
        if before is None:
            ENV.pop("OBSW_MISSION", None)
        else:
            ENV["OBSW_MISSION"] = before
        stop(proc)


def test_a_second_terminal_sees_the_tm_of_the_first(obc, tmp_path):
    port, _ = obc
    log = tmp_path / "session.log"
    monitor, out, err = start(
        "ground", "--port", port, "monitor", "--seconds", BOUND, "--log", log, "--colour", "never"
    )
    try:
        err.until(lambda line: line.startswith("monitoring TM from"))
        assert obsw("ground", "--port", port, "ping").returncode == 0
        line = out.until(lambda line: "TM[17,2]" in line)
        assert "are-you-alive report" in line and line.startswith("20")  # UTC time first
        line = out.until(lambda line: "TM[1,7]" in line)
        assert "completion success" in line
        assert obsw("ground", "--port", port, "function", "SolarPanel.deploy").returncode == 0
        line = out.until(lambda line: "TM[5," in line)
        assert "event SolarPanel.deployed (low): hinges=3" in line
        line = out.until(lambda line: "TM[3,25]" in line)  # periodic housekeeping, with units
        assert "SolarPanel.speed=5 deg/s" in line
        # a third client, listening for events only, sees an event the first client caused
        listen, levents, lerr = start(
            "ground", "--port", port, "events", "listen", "--seconds", 20
        )
        try:
            lerr.until(lambda line: line.startswith("listening for TM[5,*]"))
            turn = obsw("ground", "--port", port, "function", "SolarPanel.set_angle", "angle=10")
            assert turn.returncode == 0
            line = levents.until(lambda line: "SolarPanel.angle_reached" in line)
            assert "angle=10" in line
        finally:
            stop(listen)
    finally:
        stop(monitor)
    replay = obsw("ground", "replay", log, "--colour", "never")
    assert replay.returncode == 0, replay.stderr
    assert "TM[17,2] are-you-alive report" in replay.stdout
    records = [json.loads(x) for x in log.read_text().splitlines()]
    assert {r["dir"] for r in records} == {"TM"} and all(r["raw"] for r in records)


def test_session_log_of_commands_and_its_replay(obc, tmp_path):
    port, _ = obc
    log = tmp_path / "s.log"
    assert obsw("ground", "--port", port, "--log", log, "ping").returncode == 0
    records = [json.loads(x) for x in log.read_text().splitlines()]
    assert records[0]["dir"] == "TC" and "TC[17,1]" in records[0]["text"]
    assert [r["dir"] for r in records].count("TM") >= 4
    replay = obsw("ground", "replay", log)
    lines = replay.stdout.splitlines()
    assert "TC[17,1] are-you-alive" in lines[0]
    assert any("TC[17,1] are-you-alive: completion success" in x for x in lines)


def test_readable_replies(obc):
    port, _ = obc
    ping = obsw("ground", "--port", port, "ping")
    assert ping.stdout.splitlines()[-1] == "alive"
    obsw("ground", "--port", port, "schedule", "insert", "--at", "2031-01-01T00:00:00Z", "ping")
    listing = obsw("ground", "--port", port, "schedule", "list").stdout
    assert "2031-01-01T00:00:00.000Z" in listing and "TC[17,1] are-you-alive" in listing
    failed = obsw("ground", "--port", port, "function", "SolarPanel.set_angle", "angle=5")
    assert failed.returncode == 1
    assert "completion failure: component error (code 13) (function SolarPanel.set_angle: " in (
        failed.stdout
    )
    hk = obsw("ground", "--port", port, "hk", "report", "1").stdout
    assert "SolarPanel.angle = 0 deg" in hk


def test_onboard_log_one_line_per_tc(obc):
    port, err = obc
    assert obsw("ground", "--port", port, "ping").returncode == 0
    assert " INFO obsw.onboard: TC apid 10 seq " in err.until(lambda x: "accepted" in x)
    obsw("ground", "--port", port, "function", "SolarPanel.set_angle", "angle=5")
    line = err.until(lambda x: "failure" in x)
    assert "WARNING" in line and "component error" in line


@pytest.mark.parametrize(
    "kind, expected",
    [
        ("parameters", "2 SolarPanel.speed float32 deg/s yes [0.1, 20]"),
        ("functions", "2 SolarPanel.set_angle angle: float32"),
        ("events", "2 SolarPanel.deployed low hinges: uint8"),
        ("hk", "1 10 yes SolarPanel.angle, SolarPanel.speed, SolarPanel.is_deployed"),
    ],
)
def test_discovery_from_the_database(kind, expected):
    result = obsw("ground", "--mission", os.path.join(ROOT, "examples", "sample"), "list", kind)
    rows = [" ".join(line.split()) for line in result.stdout.splitlines()]
    assert result.returncode == 0 and " ".join(expected.split()) in rows, rows


def test_version_and_json_anywhere(obc):
    port, _ = obc
    assert obsw("--version").stdout.startswith("obsw ")
    for args in (
        ("--json", "ground", "--port", port, "ping"),
        ("ground", "--port", port, "ping", "--json"),
    ):
        assert json.loads(obsw(*args).stdout)["replies"] == [{"alive": True}]
