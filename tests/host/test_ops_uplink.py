"""`obsw ops uplink`: the predicted passes as the onboard pass table, both ways: the windows
the ground makes (onboard time, merged, bounded) and the table a real `obsw obc serve` takes
(its ``Passes.passes`` read back through service 20), and a bad table refused on board."""

import json

import pytest
from obsw_host.obc.passes import unpack_table
from obsw_host.ops.pass_table import LIMIT, table, windows
from obsw_host.pus.tai import TAI_MINUS_UNIX
from obsw_host.sample import SDB_PATH
from test_cli_ground import ENV, Lines, free_base, obsw, start, stop

ORBIT = {
    "name": "SAMPLE-SAT",
    "tle": [
        "1 99001U 26001A   26332.50000000  .00001000  00000-0  50000-4 0  9999",
        "2 99001  97.4000 330.0000 0001000  90.0000 270.0000 15.20000000   105",
    ],
    "epoch": "2026-11-28T12:00:00Z",
}
STATIONS = [
    {"name": "munich", "latitude": 48.15, "longitude": 11.57, "altitude": 520,
     "min_elevation": 10, "uplink_bps": 9600, "downlink_bps": 38400},
    {"name": "graz", "latitude": 47.07, "longitude": 15.44, "altitude": 400,
     "min_elevation": 5, "uplink_bps": 9600, "downlink_bps": 38400},
]  # fmt: skip


class P:
    def __init__(self, aos, los):
        self.aos, self.los = aos, los


def test_windows_merged_ordered_in_onboard_time():
    passes = [P(300.2, 400.5), P(100.0, 200.0), P(150.0, 250.0), P(250.0, 260.0)]
    ws = windows(passes, offset=0)
    assert ws == [(100, 260), (301, 400)]  # overlapping and touching passes: one window
    assert windows([P(10.2, 10.9), P(20.5, 21.5)], offset=0) == []  # no whole second inside
    assert windows([P(0.0, 1.0)])[0][0] == TAI_MINUS_UNIX
    many = [P(i * 100.0, i * 100.0 + 50) for i in range(100)]
    assert len(windows(many)) == LIMIT
    assert unpack_table(table(passes, offset=0)) == ws


@pytest.fixture
def obc(tmp_path):
    """`obsw obc serve` of a mission with an orbit, two stations and the PUS process."""
    base = free_base()
    mission = tmp_path / "mission.json"
    mission.write_text(json.dumps({
        "format": 2, "name": "test-uplink", "sdb": SDB_PATH, "state": "state",
        "processes": {"obc": ["pus", "SolarPanel"]}, "pus": {"apid": 10, "period": 0.1},
        "components": {"SolarPanel": {"module": "obsw_host.solar_panel"}},
        "orbit": ORBIT, "stations": STATIONS,
    }))  # fmt: skip
    env = dict(ENV, OBSW_PORT_BASE=str(base))
    proc, out, err = start("obc", "serve", mission, env=env)
    Lines.merged(out, err).until(lambda line: " up: " in line)
    try:
        yield mission, base + 10
    finally:
        stop(proc)


def test_uplink_to_a_running_obc(obc):
    mission, port = obc
    args = ["--mission", mission, "--start", "2026-11-28T12:00:00Z"]
    r = obsw("ops", "uplink", *args, "--days", "2", "--port", port)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "completion success" in r.stdout, r.stdout
    n = int(r.stdout.split(" windows in the table")[0].split()[-1])
    assert n >= 4
    got = obsw(
        "ground", "--mission", mission, "--port", port, "--json", "params", "get", "Passes.passes"
    )
    assert got.returncode == 0, got.stdout + got.stderr
    assert str(n) in got.stdout, got.stdout
    # more passes than the table holds: the first 64, said so
    r = obsw("ops", "uplink", *args, "--days", "20", "--port", port)
    assert r.returncode == 0 and "beyond the table's 64" in r.stdout, r.stdout + r.stderr
    # a bad table is refused on board with its reason, the table in force kept
    from obsw.pus import sdb as sdb_module
    from obsw_host.pus.ground import Ground

    with Ground(sdb_module.load(SDB_PATH), target=("127.0.0.1", port), timeout=10.0) as g:
        bad = g.perform("Passes.load", table=bytes(12))
        report = " ".join(bad.verification())
        assert not bad.ok and b"BAD_TABLE".hex() in report, report
        assert g.get_parameters("Passes.passes").reply["values"]["Passes.passes"] == LIMIT
