"""A newcomer's stumbles, each through the real `obsw` as typed: one line and status 2 for a
mistake, never a traceback, and help that says what the code does."""

import json
import os
import socket
import subprocess

from obsw_host.sample import SDB_PATH
from test_cli_ground import BOUND, ENV, OBSW, ROOT, Lines, free_base, obsw, start, stop

SAMPLE = os.path.join(ROOT, "examples", "sample")


def test_a_word_for_a_number_is_one_line_without_an_obc():
    """`params set SolarPanel.speed=fast` (a parameter with a range): one line, status 2."""
    r = obsw("ground", "params", "set", "SolarPanel.speed=fast")
    assert r.returncode == 2, r.stderr
    assert r.stderr.strip().splitlines() == [
        "obsw ground: SolarPanel.speed: 'fast' is not a number"
    ]


def test_the_mission_help_states_the_order_locate_follows():
    """`--mission`'s help: $OBSW_MISSION first, then the nearest mission.json (as ``locate``)."""
    for argv in (("ground", "--help"), ("yamcs", "config", "--help")):
        text = " ".join(obsw(*argv).stdout.split())
        assert "(default: $OBSW_MISSION, else the nearest mission.json from here up)" in text


def test_a_taken_pus_port_is_one_line_naming_it(tmp_path):
    """`obsw obc serve sample` with its PUS port held by another program: one line that names
    the port, and nothing started."""
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    try:
        base = s.getsockname()[1] - 10  # the sample's PUS APID is 10
        r = subprocess.run(
            OBSW + ["obc", "serve", SAMPLE, "--state", str(tmp_path / "state")],
            env=dict(ENV, OBSW_PORT_BASE=str(base)),
            capture_output=True,
            text=True,
            timeout=BOUND,
        )
    finally:
        s.close()
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(
        "obsw obc: UDP port %d (pus) on 127.0.0.1 in use" % (base + 10)
    ), lines
    assert "Traceback" not in r.stderr


def test_cfdp_put_of_a_file_outside_the_filestore_names_the_folder(tmp_path):
    """`obsw cfdp put img.bin` with img.bin beside the filestore, not in it: the line names the
    folder it looked in and how to name another."""
    (tmp_path / "img.bin").write_bytes(b"image")
    for name in ("img.bin", str(tmp_path / "img.bin")):
        r = obsw("cfdp", "put", name, cwd=str(tmp_path))
        assert r.returncode == 2, r.stderr
        assert r.stderr.startswith(
            "obsw cfdp: no file %s in the filestore folder filestore/" % name
        )
        assert "--root" in r.stderr


def test_watch_shows_loss_of_signal_when_the_obc_dies(tmp_path):
    """`obsw ground watch`: while TM comes, how long ago; when the OBC dies, LOSS OF SIGNAL
    and every value kept but marked stale. With no TM at all, `--once` exits 1."""
    base = free_base()
    mission = tmp_path / "mission.json"
    mission.write_text(json.dumps({
        "format": 2, "name": "los", "sdb": SDB_PATH, "state": "state",
        "processes": {"obc": ["pus", "SolarPanel"]},
        "components": {"SolarPanel": {"module": "obsw_host.solar_panel"}},
        "pus": {"apid": 10, "period": 0.1},
    }))  # fmt: skip
    env = dict(ENV, OBSW_PORT_BASE=str(base), OBSW_MISSION=str(mission))
    obc, out, err = start("obc", "serve", mission, env=env)
    try:
        Lines.merged(out, err).until(lambda line: " up: " in line)
        watch, wout, _ = start("ground", "--json", "watch", "--every", "0.3", "--los", "1.5",
                               "--seconds", BOUND, env=env)  # fmt: skip
        frames = wout
        try:
            frame = json.loads(frames.until(lambda line: not json.loads(line)["signal"]["lost"]))
            assert frame["signal"]["text"].startswith("last TM"), frame["signal"]
            stop(obc)  # the OBC dies
            frame = json.loads(frames.until(lambda line: json.loads(line)["signal"]["lost"]))
            assert frame["signal"]["text"].startswith("LOSS OF SIGNAL: no TM for"), frame["signal"]
            assert any(v["name"] == "SolarPanel.speed" for v in frame["values"])
        finally:
            stop(watch)
    finally:
        if obc.poll() is None:
            stop(obc)
    r = subprocess.run(OBSW + ["ground", "--timeout", "0.3", "watch", "--once"], env=env,
                       capture_output=True, text=True, timeout=BOUND)  # fmt: skip
    assert r.returncode == 1
    assert "no TM from 127.0.0.1:%d" % (base + 10) in r.stderr


def test_the_console_history_of_the_sample_stays_out_of_the_source_tree():
    """A mission file that names no state folder (the sample) keeps its state, the console's
    history with it, in the user's state folder, never beside the mission in the checkout."""
    import argparse

    from obsw_host.commands.ground_tui import history_path
    from obsw_host.mission.ids import MissionIds

    path = history_path(argparse.Namespace(history=None), MissionIds.locate(SAMPLE))
    assert not os.path.abspath(path).startswith(ROOT + os.sep), path


def test_obsw_help_lists_commands_in_the_order_a_team_works():
    """`obsw --help` starts with the mission, then the OBC, then the ground."""
    text = obsw("--help").stdout
    at = [text.index("\n    %s " % name) for name in ("mission", "obc", "ground")]
    assert at == sorted(at), text


def test_fly_your_own_spacecraft_is_where_a_newcomer_looks():
    for page in ("README.md", "docs/index.md", "docs/getting-started.md"):
        with open(os.path.join(ROOT, page), encoding="utf-8") as f:
            assert "fly-your-own-spacecraft.md" in f.read(), page


def test_obcp_status_with_no_obc_names_where_it_asked():
    base = free_base()
    r = subprocess.run(OBSW + ["obcp", "--timeout", "0.3", "status"],
                       env=dict(ENV, OBSW_PORT_BASE=str(base)), capture_output=True, text=True,
                       timeout=BOUND)  # fmt: skip
    assert r.returncode == 1
    assert (
        "no report from 127.0.0.1:%d within 0.3s: is `obsw obc serve` running" % (base + 10)
        in r.stdout
    )
