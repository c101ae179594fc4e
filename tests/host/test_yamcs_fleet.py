"""Several spacecraft on one Yamcs server (``obsw yamcs config|run --mission A --mission B ...``).

Three missions made from the sample by ``obsw mission new --count 3`` (each its own name,
spacecraft id and port base), each running as its own ``obsw obc serve``; one ``obsw yamcs run``
with an instance per mission: each instance receives its own spacecraft's housekeeping, and a
command sent to each instance completes through service 1 on that spacecraft only. Before
that, without Java: the configuration one instance per mission, and missions that clash
refused in one line before anything starts. The Yamcs tests are skipped with the reason
without Java or the Yamcs jars.
"""

import os
import re
import socket
import subprocess
import sys

import pytest
from obsw_host.ids import MissionIds
from obsw_host.mission import new
from obsw_host.mission.check import check
from obsw_host.yamcs import fleet, server
from test_yamcs_aurora import _start, _stop
from test_yamcs_e2e import Watch

MISSING = server.missing()
needs_yamcs = pytest.mark.skipif(MISSING is not None, reason=str(MISSING))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SAMPLE = os.path.join(ROOT, "examples", "sample")
OBSW = [sys.executable, "-m", "obsw_host.cli"]
TIMEOUT = 30.0
COUNT = 3


@pytest.fixture(autouse=True)
def _no_port_base(monkeypatch):
    monkeypatch.delenv("OBSW_PORT_BASE", raising=False)  # each mission's own base


def _env(**extra):
    env = {k: v for k, v in os.environ.items() if k not in ("OBSW_PORT_BASE", "OBSW_MISSION")}
    env.update(extra)
    return env


def _obsw(*argv, cwd=None):
    return subprocess.run(
        OBSW + list(argv), env=_env(), cwd=cwd, capture_output=True, text=True, timeout=120
    )


def _all_ports(ids):
    return set(ids.ports.table().values())


def free_fleet_base(count, step=new.FLEET_STEP):
    """A port base for ``count`` missions ``step`` apart with every port of theirs free."""
    for base in range(30000, 60000 - count * step - 5100, 997):
        ports = set()
        for k in range(count):
            b = base + k * step
            ports |= {b - 1, b, b + 10, b + 100, b + 101, b + 3090} | set(
                range(b + 5015, b + 5019)
            )
        try:
            for port in ports:
                for kind in (socket.SOCK_DGRAM, socket.SOCK_STREAM):
                    s = socket.socket(socket.AF_INET, kind)
                    try:
                        s.bind(("127.0.0.1", port))
                    finally:
                        s.close()
        except OSError:
            continue
        return base
    raise RuntimeError("no free port base for %d missions" % count)


# ------------------------------------------------------------------------------ without Java


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


# ------------------------------------------------------------------------------ with Yamcs


class Fleet:
    """Three `obsw obc serve` and one `obsw yamcs run` operating them, with Yamcs' client."""

    def __init__(self, work):
        from yamcs.client import YamcsClient

        base = free_fleet_base(COUNT)
        self.folders = new.fleet(SAMPLE, "fleet", work, COUNT, port_base=base)
        self.missions = [MissionIds.locate(f) for f in self.folders]
        self.names = [ids.name for ids in self.missions]
        env = _env(OBSW_STATE=os.path.join(work, "state"))
        self.procs = []
        obcs = []
        try:
            for folder in self.folders:
                proc, out = _start(OBSW + ["obc", "serve", folder], env, work)
                self.procs.append(proc)
                obcs.append(out)
            argv = ["yamcs", "run", "--dir", os.path.join(work, "y")]
            for folder, ids, out in zip(self.folders, self.missions, obcs):
                line = out.until(lambda x: x.startswith("PUS application process"))
                port = int(line.split(" on udp ")[1].split(",")[0].split(":")[1])
                assert port == ids.ports.pus
                argv += ["--mission", folder, "--obc", "127.0.0.1:%d" % port]
            proc, self.yamcs_out = _start(OBSW + argv, env, work)
            self.procs.append(proc)
            self.yamcs_out.until(lambda x: x.startswith("Yamcs ") and " on http" in x, 150)
        except BaseException:
            self.close()
            raise
        self.client = YamcsClient("127.0.0.1:%d" % self.missions[0].ports.yamcs_http)
        self.values = {}
        self.commands = {}
        self.subscriptions = []
        for name in self.names:
            processor = self.client.get_processor(name, "realtime")
            self.commands[name] = processor.create_command_connection()
            watch = self.values[name] = Watch()

            def on_values(data, watch=watch):
                for pv in data.parameters:
                    watch(pv)

            params = ["/%s/SolarPanel/%s" % (name, p) for p in ("angle", "speed")]
            self.subscriptions.append(
                processor.create_parameter_subscription(params, on_data=on_values)
            )

    def issue(self, name, command, args=None):
        cmd = self.commands[name].issue("/%s/%s" % (name, command), args=args)
        cmd.await_complete(timeout=TIMEOUT)
        return cmd

    def speed(self, name, since):
        """The first speed in instance ``name``'s housekeeping from index ``since`` on."""
        pv = self.values[name].wait(lambda v: v.name.endswith("/speed"), since)
        return pv.eng_value

    def close(self):
        for proc in reversed(self.procs):
            _stop(proc)


@pytest.fixture(scope="module")
def ground(tmp_path_factory):
    if MISSING is not None:
        pytest.skip(MISSING)
    f = Fleet(str(tmp_path_factory.mktemp("fleet-yamcs")))
    yield f
    f.close()


@needs_yamcs
def test_each_instance_receives_its_own_spacecrafts_housekeeping(ground):
    for name in ground.names:
        pv = ground.values[name].wait(lambda v, n=name: v.name == "/%s/SolarPanel/angle" % n)
        assert pv.eng_value is not None
        link = ground.client.get_link(name, "pus").get_info()
        assert link.status == "OK" and link.in_count > 0


@needs_yamcs
def test_a_command_to_each_instance_completes_on_its_own_spacecraft_only(ground):
    first = 5.0  # the sample panel's speed at start
    # each its own, none the first, all within the database's limits (and exact in float32)
    speeds = {name: 2.5 + k for k, name in enumerate(ground.names)}
    now = {name: first for name in ground.names}
    for name in ground.names:
        since = ground.values[name].mark()
        cmd = ground.issue(name, "SolarPanel/set_speed", {"value": speeds[name]})
        assert cmd.is_success(), cmd.error
        acks = cmd.acknowledgments
        for stage in ("Verifier_Accepted", "Verifier_Started", "Verifier_Completed"):
            assert acks[stage].status == "OK", (name, stage)
        now[name] = speeds[name]
        after = {n: ground.values[n].mark() for n in ground.names}
        # its spacecraft reports the new speed; every other one still reports its own
        ground.values[name].wait(
            lambda v, s=speeds[name]: v.name.endswith("/speed") and v.eng_value == s, since
        )
        for other in ground.names:
            if other != name:
                assert ground.speed(other, after[other]) == now[other], (name, other)
    for name in ground.names:  # in the end each one has its own
        assert ground.speed(name, ground.values[name].mark()) == speeds[name]


@needs_yamcs
def test_a_ping_to_each_instance_completes_through_service_1(ground):
    for name in ground.names:
        cmd = ground.issue(name, "PUS/ping")
        assert cmd.is_success(), (name, cmd.error)
        assert cmd.acknowledgments["Verifier_Completed"].status == "OK"
