"""The mission file's orbit and stations, as `obsw mission check` sees them, and `obsw ops
passes|plan` on the sample."""

import json
import os
import shutil

import pytest
from obsw_host import sample
from obsw_host.cli import main
from obsw_host.mission.check import check
from obsw_host.ops.tle import checksum


@pytest.fixture
def folder(tmp_path):
    dst = str(tmp_path / "m")
    shutil.copytree(sample.MISSION_DIR, dst, ignore=shutil.ignore_patterns("__pycache__"))
    return dst


def _edit(folder, change):
    path = os.path.join(folder, "mission.json")
    with open(path) as f:
        doc = json.load(f)
    change(doc)
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)


def _problems(folder):
    _, problems = check(os.path.join(folder, "mission.json"))
    return [str(p) for p in problems]


def test_the_sample_has_an_orbit_and_a_station(folder):
    assert _problems(folder) == []


def _bad_checksum(d):
    line = d["orbit"]["tle"][0]
    d["orbit"]["tle"][0] = line[:68] + str((checksum(line) + 1) % 10)


def _other_epoch(d):
    d["orbit"]["epoch"] = "2026-11-28T12:00:01Z"


def _twice(d):
    d["stations"].append(dict(d["stations"][0]))


def _low_elevation(d):
    d["stations"][0]["min_elevation"] = -1


def _no_rate(d):
    del d["stations"][0]["downlink_bps"]


def _no_orbit(d):
    del d["orbit"]


@pytest.mark.parametrize(
    "change, path, words",
    [
        (_bad_checksum, "$.orbit", "checksum"),
        (_other_epoch, "$.orbit.epoch", "expected the TLE's epoch 2026-11-28T12:00:00.000Z"),
        (_twice, "$.stations[1].name", "named twice"),
        (_low_elevation, "$.stations[0].min_elevation", ""),
        (_no_rate, "$.stations[0]", "downlink_bps"),
        (_no_orbit, "$.stations", "without an orbit"),
    ],
)
def test_each_mistake_is_one_line(folder, change, path, words):
    _edit(folder, change)
    problems = _problems(folder)
    assert len(problems) == 1, problems
    assert (": %s: " % path) in problems[0] and words in problems[0], problems


def test_passes_json(folder, capsys):
    argv = ["ops", "passes", "--mission", folder, "--start", "2026-11-28T12:00:00Z", "--days",
            "1", "--json"]  # fmt: skip
    assert main(argv) == 0
    rows = json.loads(capsys.readouterr().out)["passes"]
    assert len(rows) >= 4
    for r in rows:
        assert r["station"] == "ground" and r["aos"] < r["tca"] < r["los"]
        # the duration is rounded to 0.1 s in the listing
        assert abs(r["downlink_octets"] - 38400 * r["duration"] / 8) <= 38400 * 0.05 / 8 + 1


def test_unknown_station_is_a_user_error(folder, capsys):
    argv = ["ops", "passes", "--mission", folder, "--station", "nowhere"]
    assert main(argv) == 2
    assert "no station 'nowhere'; expected one of ground" in capsys.readouterr().err


def test_plan_then_check_against_a_schedule_report(folder, tmp_path, capsys):
    base = ["ops", "plan", "--mission", folder, "--start", "2026-11-28T12:00:00Z", "--json"]
    assert main(base) == 0
    steps = json.loads(capsys.readouterr().out)["plan"]
    assert [s["what"] for s in steps[:2]] == ["transmitter on", "transmitter off"]
    report = {"activities": [{"time": s["time"] + 0.5, "request": s["request"]} for s in steps]}
    path = str(tmp_path / "report.json")
    with open(path, "w") as f:
        json.dump(report, f)
    assert main(base + ["--report", path]) == 0
    assert json.loads(capsys.readouterr().out)["ok"] is True
    report["activities"].pop()
    report["activities"][0]["time"] += 2.0  # beyond the 1 s tolerance
    with open(path, "w") as f:
        json.dump(report, f)
    assert main(base + ["--report", path]) == 2
    out = json.loads(capsys.readouterr().out)
    assert len(out["problems"]) == 3  # two missing, one unplanned


def test_close_passes_share_one_transmitter_window():
    from obsw_host.ops.passes import Pass, Station
    from obsw_host.ops.plan import plan

    a, b = Station("a", 0, 0, 0, 10, 1, 1), Station("b", 0, 1, 0, 10, 1, 1)
    steps = plan([Pass(a, 1000, 1100, 1200, 30), Pass(b, 1289, 1300, 1400, 30)], 60, 30)
    assert [(s.time, s.what) for s in steps] == [(940, "transmitter on"),
                                                 (1430, "transmitter off")]  # fmt: skip
    steps = plan([Pass(a, 1000, 1100, 1200, 30), Pass(b, 1291, 1300, 1400, 30)], 60, 30)
    assert len(steps) == 4  # 1 s beyond lead + lag: two windows
