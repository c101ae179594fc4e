"""Several spacecraft for one Yamcs server, before Yamcs runs: ``obsw mission new --count N``
writes missions with their own names, spacecraft ids and ports; ``obsw yamcs config --mission A
--mission B ...`` writes an instance per mission (Yamcs' own ``--check`` accepts it, skipped
with the reason without Java); missions that share a spacecraft id, a port or a name are refused
in one line before anything is written or started. ``test_yamcs_fleet`` runs such a fleet."""

import os
import re
import subprocess
import sys

import pytest
from obsw_host.mission import new
from obsw_host.mission.check import check
from obsw_host.mission.ids import MissionIds
from obsw_host.yamcs import fleet, server

MISSING = server.missing()
needs_yamcs = pytest.mark.skipif(MISSING is not None, reason=str(MISSING))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SAMPLE = os.path.join(ROOT, "examples", "sample")
OBSW = [sys.executable, "-m", "obsw_host.cli"]
COUNT = 3


@pytest.fixture(autouse=True)
def _no_port_base(monkeypatch):
    monkeypatch.delenv("OBSW_PORT_BASE", raising=False)  # each mission's own base


def _env(**extra):
    """The environment of the fleet's processes: each mission its own base and folder."""
    env = {k: v for k, v in os.environ.items() if k not in ("OBSW_PORT_BASE", "OBSW_MISSION")}
    env.update(extra)
    return env


def _obsw(*argv, cwd=None):
    return subprocess.run(
        OBSW + list(argv), env=_env(), cwd=cwd, capture_output=True, text=True, timeout=120
    )


def _all_ports(ids):
    return set(ids.ports.table().values())


def test_mission_new_count_writes_missions_with_their_own_ids_and_ports(tmp_path):
    r = _obsw("mission", "new", "sat", "--count", "3", "--from", SAMPLE, "--dir", str(tmp_path))
    assert r.returncode == 0, r.stderr
    folders = [str(tmp_path / ("sat-%d" % k)) for k in (1, 2, 3)]
    missions = [MissionIds.locate(f) for f in folders]
    assert [m.name for m in missions] == ["sat-1", "sat-2", "sat-3"]
    sample = MissionIds.locate(SAMPLE)
    assert [m.scid for m in missions] == [sample.scid + k for k in (1, 2, 3)]
    assert [m.ports.base for m in missions] == [20000, 20200, 20400]
    for a in range(3):
        for b in range(a):
            assert not _all_ports(missions[a]) & _all_ports(missions[b])
    assert fleet.problems(missions) == []
    for f in folders:
        _, problems = check(os.path.join(f, "mission.json"))
        assert problems == []


def test_mission_new_from_a_mission_moves_the_ports_its_file_fixes(tmp_path):
    aurora = os.path.join(ROOT, "examples", "aurora")
    folder = new.copy(aurora, "aurora-2", str(tmp_path / "a2"), scid=500, port_base=30000)
    ids = MissionIds.locate(folder)
    assert (ids.name, ids.scid, ids.ports.base) == ("aurora-2", 500, 30000)
    assert ids.ports.tm == MissionIds.locate(aurora).ports.tm - 5000 + 30000  # frames.tm_port
    _, problems = check(os.path.join(folder, "mission.json"))
    assert problems == []


@pytest.fixture(scope="module")
def three(tmp_path_factory):
    work = tmp_path_factory.mktemp("fleet")
    return [str(f) for f in new.fleet(SAMPLE, "fleet", str(work), COUNT)]


def test_config_writes_one_instance_per_mission(three, tmp_path):
    out = tmp_path / "y"
    argv = ["yamcs", "config", str(out)]
    for f in three:
        argv += ["--mission", f]
    r = _obsw(*argv)
    assert r.returncode == 0, r.stderr
    etc = out / "etc"
    server_yaml = (etc / "yamcs.yaml").read_text()
    missions = [MissionIds.locate(f) for f in three]
    assert "port: %d" % missions[0].ports.yamcs_http in server_yaml
    for ids in missions:
        name = ids.name
        assert '- "%s"' % name in server_yaml
        text = (etc / ("yamcs.%s.yaml" % name)).read_text()
        links = ids.ports.yamcs()
        assert re.findall(r"port: (\d+)", text) == [str(links["pus"]), str(links["cfdp"])]
        assert 'spec: "mdb/%s.xml"' % name in text
        assert 'eventTemplateFile: "etc/events.%s.json"' % name in text
        assert 'sqlFile: "etc/extra_streams.%s.sql"' % name in text
        mdb = (out / "mdb" / ("%s.xml" % name)).read_text()
        assert '<SpaceSystem name="%s"' % name in mdb
        assert (out / "files" / name / "up").is_dir()


@needs_yamcs
def test_yamcs_accepts_the_fleets_configuration(three, tmp_path):
    out = str(tmp_path / "y")
    argv = ["yamcs", "config", out]
    for f in three:
        argv += ["--mission", f]
    assert _obsw(*argv).returncode == 0
    r = _obsw("yamcs", "check", out)
    assert r.returncode == 0, r.stdout + r.stderr


def _refused(argv, folder):
    r = _obsw(*argv)
    assert r.returncode == 2, (r.stdout, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr
    assert not os.path.exists(folder)  # nothing written, nothing started
    return lines[0]


def test_missions_that_share_a_spacecraft_id_are_refused_in_one_line(three, tmp_path):
    twin = new.copy(three[0], "twin", str(tmp_path / "twin"), port_base=40000)
    out = str(tmp_path / "y")
    line = _refused(["yamcs", "config", out, "--mission", three[0], "--mission", twin], out)
    scid = MissionIds.locate(three[0]).scid
    assert "fleet-1 and twin both have spacecraft id %d" % scid in line


def test_missions_that_share_a_port_are_refused_in_one_line(three, tmp_path):
    twin = new.copy(three[1], "twin", str(tmp_path / "twin"), scid=900)  # fleet-2's ports
    out = str(tmp_path / "y")
    line = _refused(["yamcs", "config", out, "--mission", three[1], "--mission", twin], out)
    pus = MissionIds.locate(three[1]).ports.pus
    assert "fleet-2 and twin both use port %d" % pus in line
    assert '"ports": {"base": N}' in line


def test_one_mission_twice_is_refused_in_one_line(three, tmp_path):
    out = str(tmp_path / "y")
    line = _refused(["yamcs", "config", out, "--mission", three[0], "--mission", three[0]], out)
    assert "both Yamcs instance 'fleet-1'" in line


def test_run_refuses_before_starting_anything(three, tmp_path):
    out = str(tmp_path / "y")
    argv = ["yamcs", "run", "--dir", out, "--mission", three[0], "--mission", three[1]]
    line = _refused(argv + ["--obc", "127.0.0.1:1"], out)
    assert "1 --obc for 2 --mission" in line
    line = _refused(argv + ["--pus-port", "10015"], out)
    assert "--pus-port with 2 missions" in line
