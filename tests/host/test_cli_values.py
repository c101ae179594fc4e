"""Engineering values through the real `obsw ground` against `obsw obc serve`: calibrated values
shown with their unit and raw beside them, `--raw`, ranges refused before sending, limits in
engineering units on an integer parameter, functional monitoring and parameter definitions."""

import json
import os
import shutil

import pytest
from obsw_host.sample import SDB_PATH
from test_cli_ground import BOUND, ENV, Lines, free_base, obsw, start, stop


@pytest.fixture
def obc(tmp_path):
    """The sample spacecraft with SolarPanel.speed calibrated (engineering = 2 x raw)."""
    with open(SDB_PATH) as f:
        doc = json.load(f)
    for comp in doc["components"]:
        for a in comp.get("attributes", ()):
            if (comp["name"], a["name"]) == ("SolarPanel", "speed"):
                a["calibration"] = {"polynomial": [0, 2]}
                a["raw_unit"] = "half-deg/s"
    sdb = tmp_path / "sdb.json"
    sdb.write_text(json.dumps(doc))
    shutil.copytree(os.path.join(os.path.dirname(SDB_PATH), "nodes"), tmp_path / "nodes")
    mission = tmp_path / "mission.json"
    mission.write_text(
        json.dumps(
            {
                "format": 2,
                "name": "test-values",
                "sdb": str(sdb),
                "state": "state",
                "processes": {"obc": ["pus", "SolarPanel"]},
                "components": {"SolarPanel": {"module": "obsw_host.solar_panel"}},
                "pus": {"apid": 10, "period": 0.1},
            }
        )
    )
    base = free_base()
    proc, out, err = start("obc", "serve", mission, env=dict(ENV, OBSW_PORT_BASE=str(base)))
    both = Lines.merged(out, err)
    both.until(lambda line: " up: " in line)
    yield [str(base + 10), "--sdb", str(sdb), "--timeout", str(BOUND / 3)]
    stop(proc)


def ground(obc, *args):
    port, *rest = obc
    return obsw("ground", "--port", port, *rest, *args)


def test_engineering_values_raw_on_request_and_ranges(obc):
    r = ground(obc, "params", "set", "SolarPanel.speed=8")  # engineering: raw 4
    assert r.returncode == 0, r.stdout + r.stderr
    r = ground(obc, "params", "get", "SolarPanel.speed")
    assert "SolarPanel.speed = 8 deg/s (raw 4)" in r.stdout
    r = ground(obc, "--raw", "params", "get", "SolarPanel.speed")
    assert "SolarPanel.speed = 4 half-deg/s" in r.stdout
    r = ground(obc, "params", "set", "SolarPanel.speed=30")  # range [0.1, 20]: refused here
    assert r.returncode == 2
    assert "SolarPanel.speed: 30.0 outside the range [0.1, 20]" in r.stderr
    assert "TC" not in r.stdout
    r = ground(obc, "--raw", "params", "set", "SolarPanel.speed=11")  # raw 11 is 22 deg/s
    assert r.returncode == 2 and "outside the range" in r.stderr
    r = ground(obc, "--raw", "params", "set", "SolarPanel.speed=9")
    assert r.returncode == 0
    r = ground(obc, "--json", "params", "get", "SolarPanel.speed")
    assert json.loads(r.stdout)["replies"][0]["values"] == {"SolarPanel.speed": 9.0}
    r = ground(obc, "params", "set", "SolarPanel.angle=1")  # read-only: refused on board
    assert r.returncode == 1 and "refused (code 10) (parameter SolarPanel.angle)" in r.stdout


def test_limits_in_engineering_units_on_an_integer_parameter(obc):
    r = ground(obc, "monitor", "add", "1", "CpduN.state_bits", "0", "100.5")
    assert r.returncode == 0, r.stdout + r.stderr
    r = ground(obc, "--json", "monitor", "list")
    (item,) = json.loads(r.stdout)["replies"][0]["items"]
    assert (item["low"], item["high"], item["enabled"]) == (0, 100, True)
    r = ground(obc, "monitor", "add", "2", "SolarPanel.speed", "1", "10")  # eng: raw 0.5..5
    assert r.returncode == 0
    r = ground(obc, "--json", "monitor", "list")
    items = json.loads(r.stdout)["replies"][0]["items"]
    assert [(i["low"], i["high"]) for i in items] == [(0, 100), (0.5, 5.0)]
    r = ground(obc, "monitor", "list")
    assert "10 deg/s" in r.stdout  # the table shows engineering limits
    r = ground(obc, "--raw", "monitor", "add", "3", "CpduN.state_bits", "1.5", "3")
    assert r.returncode == 2 and "raw limit 1.5 of an integer parameter" in r.stderr
    r = ground(obc, "--raw", "monitor", "add", "3", "SolarPanel.speed", "1", "3")  # raw 2..6
    assert r.returncode == 0
    r = ground(obc, "--json", "monitor", "list")
    items = json.loads(r.stdout)["replies"][0]["items"]
    assert (items[-1]["low"], items[-1]["high"]) == (1.0, 3.0)


def test_functional_monitoring_and_definitions(obc):
    assert ground(obc, "monitor", "add", "1", "SolarPanel.speed", "1", "10").returncode == 0
    r = ground(obc, "fmon", "add", "7", "1", "--event", "SolarPanel.deployed")
    assert r.returncode == 0, r.stdout + r.stderr
    assert ground(obc, "fmon", "enable", "7").returncode == 0
    assert ground(obc, "fmon", "protect", "7").returncode == 0
    r = ground(obc, "fmon", "disable", "7")
    assert r.returncode == 1 and "refused" in r.stdout
    r = ground(obc, "fmon", "status")
    assert r.returncode == 0
    assert r.stdout.split("\n")[-2].split()[:3] == ["7", "yes", "yes"]
    r = ground(obc, "params", "definitions", "SolarPanel.speed")
    assert "component" in r.stdout
