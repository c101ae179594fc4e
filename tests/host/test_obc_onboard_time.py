"""The OBC's onboard time (``obsw_host.obc.onboard_time``): the ground's correction
(``OnboardTime.correct``, TC[8,1]) applied to the time PUS stamps and reports, accumulated,
refused when it cannot be a clock error, and kept across a restart of `obsw obc serve`."""

import json
import os
import subprocess

import pytest
from obsw.il.errors import ComponentError
from obsw_host.obc.onboard_time import OnboardTime
from obsw_host.pus.onboard import tai_now
from obsw_host.sample import SDB_PATH
from test_cli_ground import BOUND, ENV, OBSW, Lines, free_base, start, stop


def obsw(env, *args):
    return subprocess.run(
        OBSW + list(args), env=env, capture_output=True, text=True, timeout=BOUND
    )


class Clock:
    def __init__(self, t):
        self.t = t

    def __call__(self):
        return self.t


def test_a_correction_takes_the_error_off_from_when_it_came(tmp_path):
    raw = Clock(1000.0)
    ot = OnboardTime(str(tmp_path / "t.json"), raw)
    assert ot.now() == 1000.0  # no correction yet: the raw clock
    assert ot.correct(250, 20000)  # 250 ms ahead, 20 ppm fast
    assert ot.now() == pytest.approx(999.75)
    raw.t = 2000.0
    assert ot.now() == pytest.approx(2000.0 - 0.25 - 20e-6 * 1000.0)
    # the next fit is against the corrected time: its offset and drift add to what is applied
    ot.correct(-10, -5000)
    assert ot.now() == pytest.approx(2000.0 - (0.25 + 0.02) + 0.01)
    raw.t = 3000.0
    assert ot.now() == pytest.approx(3000.0 - (0.27 - 0.01) - 15e-6 * 1000.0)
    assert (ot.offset_ms, ot.drift_ppb, ot.corrections) == (260, 15000, 2)
    again = OnboardTime(str(tmp_path / "t.json"), raw)  # after a restart
    assert again.now() == pytest.approx(ot.now())
    assert (again.offset_ms, again.drift_ppb, again.corrections) == (260, 15000, 2)


@pytest.mark.parametrize("offset_ms, drift_ppb", [(10**13, 0), (0, 2 * 10**8)])
def test_what_cannot_be_a_clock_error_is_refused_and_nothing_changes(
    tmp_path, offset_ms, drift_ppb
):
    ot = OnboardTime(str(tmp_path / "t.json"), Clock(5.0))
    with pytest.raises(ComponentError) as e:
        ot.correct(offset_ms, drift_ppb)
    assert e.value.code == "OUT_OF_RANGE"
    assert ot.now() == 5.0 and not os.path.exists(tmp_path / "t.json")


def test_an_unreadable_state_file_leaves_the_raw_clock(tmp_path):
    path = tmp_path / "t.json"
    path.write_text('{"offset": ')  # cut by a power loss before the atomic rename existed
    assert OnboardTime(str(path), Clock(7.0)).now() == 7.0


def test_the_obc_reports_the_corrected_time_and_keeps_it_across_a_restart(tmp_path):
    mission = tmp_path / "mission.json"
    mission.write_text(
        json.dumps(
            {
                "format": 2,
                "name": "test-time",
                "sdb": SDB_PATH,
                "state": "state",
                "processes": {"obc": ["pus", "SolarPanel"]},
                "components": {"SolarPanel": {"module": "obsw_host.solar_panel"}},
                "pus": {"apid": 10, "period": 0.1},
            }
        )
    )
    env = dict(ENV, OBSW_PORT_BASE=str(free_base()), OBSW_MISSION=str(mission))
    for restart in (False, True):
        proc, out, err = start("obc", "serve", mission, env=env)
        try:
            Lines.merged(out, err).until(lambda line: " up: " in line)
            if not restart:
                r = obsw(env, "ground", "function", "OnboardTime.correct", "offset_ms=2000",
                         "drift_ppb=0")  # fmt: skip
                assert r.returncode == 0, r.stdout + r.stderr
            r = obsw(env, "ground", "--json", "params", "get", "OnboardTime.offset_ms")
            assert json.loads(r.stdout)["replies"][0]["values"] == {"OnboardTime.offset_ms": 2000}
            assert obsw(env, "ground", "time", "rate", "0").returncode == 0
            r = obsw(env, "ground", "--json", "time", "listen", "--seconds", "2.5")
            reports = [json.loads(x)["value"]["time"] for x in r.stdout.splitlines()]
            assert reports, r.stderr
            host = tai_now()
            # each report is 2 s behind the host's clock (less the time it took to read)
            assert all(-2.0 - 3.0 < t - host < -2.0 + 0.5 for t in reports), (reports, host)
        finally:
            stop(proc)


def test_set_from_the_ds3231_the_offset_follows_and_the_drift_stays(tmp_path):
    raw = Clock(5000.0)
    ot = OnboardTime(str(tmp_path / "t.json"), raw)
    ot.correct(0, 1000)  # 1 ppm fast
    ot.set_time(4000.0)  # the module's clock says: 1000 s earlier (a host clock after a cut)
    assert ot.now() == pytest.approx(4000.0)
    raw.t = 6000.0
    assert ot.now() == pytest.approx(5000.0 - 1e-6 * 1000.0)
    assert OnboardTime(str(tmp_path / "t.json"), raw).now() == pytest.approx(ot.now())
