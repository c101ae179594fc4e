"""Names everywhere, through the real `obsw ground` against `obsw obc serve`: failure reports
with the component's error by name and its data decoded, monitoring definitions and
out-of-limits reports by parameter, check type, check state and event with UTC times,
event-actions with their TCs decoded, time reports in UTC, file listings as tables, and
`ground replay` with the logged on-board times."""

import json
import re
import time

from obsw_host.pus.display import limit_state
from obsw_host.sample import load_sdb
from test_cli_ground import obc, obsw  # noqa: F401

UTC = re.compile(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z")


def ground(port, *args):
    return obsw("ground", "--port", port, *args)


def test_failure_reports_say_what_the_component_said(obc):  # noqa: F811 (the fixture)
    port, _ = obc
    r = ground(port, "function", "SolarPanel.set_angle", "angle=5")
    assert r.returncode == 1
    assert "(function SolarPanel.set_angle: NOT_DEPLOYED: deploy the panel before turning it)" in (
        r.stdout
    )
    assert ground(port, "function", "SolarPanel.deploy").returncode == 0
    r = ground(port, "function", "SolarPanel.set_angle", "angle=95")
    assert "ANGLE_OUT_OF_RANGE: angle 95.0 beyond the hinge limit (angle=95, limit=90)" in r.stdout
    out = json.loads(ground(port, "--json", "function", "SolarPanel.set_angle", "angle=95").stdout)
    assert out["failure_detail"].startswith("function SolarPanel.set_angle: ANGLE_OUT_OF_RANGE")


def _rows(stdout):
    return [line.split() for line in stdout.splitlines() if line.strip()]


def test_monitoring_by_name_states_and_utc_times(obc):  # noqa: F811
    port, _ = obc
    add = ground(
        port,
        "monitor",
        "add",
        1,
        "SolarPanel.speed",
        0.5,
        10,
        "--high-event",
        "SolarPanel.deployed",
    )
    assert add.returncode == 0, add.stdout + add.stderr
    listing = ground(port, "monitor", "list").stdout
    assert "SolarPanel.speed" in listing and "SolarPanel.deployed" in listing
    row = [x for x in listing.splitlines() if x.startswith("1 ")][0]
    assert " limit " in row and "0.5 deg/s" in row and "10 deg/s" in row
    assert ground(port, "params", "set", "SolarPanel.speed=12").returncode == 0
    report = ground(port, "monitor", "out-of-limits").stdout
    row = [x for x in report.splitlines() if "SolarPanel.speed" in x][0]
    assert "12 deg/s" in row and "within" in row and "above high" in row
    assert UTC.search(row), row


def test_event_actions_show_their_tcs_decoded(obc):  # noqa: F811
    port, _ = obc
    add = ground(
        port,
        "action",
        "add",
        "SolarPanel.angle_reached",
        "function",
        "SolarPanel.set_angle",
        "angle=3",
    )
    assert add.returncode == 0, add.stdout
    assert ground(port, "action", "add", "SolarPanel.deployed", "set", "SolarPanel.speed=5")
    listing = ground(port, "action", "list").stdout
    assert "TC[8,1] perform function: SolarPanel.set_angle(angle=3)" in listing
    assert "TC[20,3] set parameter values: SolarPanel.speed=5" in listing
    assert "SolarPanel.angle_reached" in listing and "SolarPanel.deployed" in listing


def test_time_reports_in_utc_and_files_as_a_table(obc):  # noqa: F811
    port, _ = obc
    assert ground(port, "time", "rate", 0).returncode == 0
    listen = ground(port, "time", "listen", "--seconds", 2.5)
    line = [x for x in listen.stdout.splitlines() if "TM[9,2]" in x][0]
    assert "e+09" not in line and len(UTC.findall(line)) == 2, line
    files = ground(port, "list", "files")
    lines = [x for x in files.stdout.splitlines() if not x.startswith("  ")]  # no stages
    assert files.returncode == 0 and lines[0] == "SAT:/" and lines[1].split() == ["name", "type"]
    assert "{" not in files.stdout


def test_replay_prints_the_logged_times_not_the_replay_time(obc, tmp_path):  # noqa: F811
    port, _ = obc
    log = tmp_path / "s.log"
    assert ground(port, "--log", log, "ping").returncode == 0
    logged = [json.loads(x)["utc"] for x in log.read_text().splitlines()]
    # a gap between the session and its replay, so the two times differ: the clock 2 s on
    end = time.monotonic() + 10.0
    while _seconds(_utc_now()) - _seconds(logged[-1]) < 2.0 and time.monotonic() < end:
        time.sleep(0.05)
    shown = [UTC.match(x).group(0) for x in obsw("ground", "replay", log).stdout.splitlines()]
    assert len(shown) == len(logged)
    for was, now in zip(logged, shown):
        assert abs(_seconds(was) - _seconds(now)) < 1.0, (was, now)


def _utc_now():
    return time.strftime("%Y-%m-%dT%H:%M:%S.000Z", time.gmtime())


def _seconds(utc):
    return time.mktime(time.strptime(utc[:19], "%Y-%m-%dT%H:%M:%S")) + float(utc[19:-1] or 0)


def test_limit_states_from_the_database():
    speed = load_sdb(None).parameter("SolarPanel.speed")  # warning 1..10, critical 0.5..15
    assert [limit_state(speed, v) for v in (5, 12, 0.7, 16, 25, True)] == [
        "ok",
        "warning",
        "warning",
        "critical",
        "out of range",  # the range is 0.1..20
        "",
    ]
