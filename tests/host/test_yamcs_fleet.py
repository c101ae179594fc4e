"""Several spacecraft on one Yamcs server (``obsw yamcs run --mission A --obc .. --mission B
--obc ..``): three missions made from the sample by ``obsw mission new --count 3`` (each its own
name, spacecraft id and port base), each running as its own ``obsw obc serve``, and one
``obsw yamcs run`` with an instance per mission. Each instance receives its own spacecraft's
housekeeping, and a command sent to each instance completes through service 1 on that
spacecraft only. Skipped with the reason without Java or the Yamcs jars.
"""

import os

import pytest
from obsw_host.mission import new
from obsw_host.mission.ids import MissionIds
from obsw_host.yamcs import server
from test_yamcs_aurora import _start, _stop
from test_yamcs_e2e import Watch
from test_yamcs_fleet_config import COUNT, OBSW, SAMPLE, _env

MISSING = server.missing()
pytestmark = pytest.mark.skipif(MISSING is not None, reason=str(MISSING))
TIMEOUT = 30.0


class Fleet:
    """Three `obsw obc serve` and one `obsw yamcs run` operating them, with Yamcs' client."""

    def __init__(self, work):
        from yamcs.client import YamcsClient

        base = new.free_fleet_base(COUNT)
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
    with pytest.MonkeyPatch.context() as mp:
        mp.delenv("OBSW_PORT_BASE", raising=False)  # each mission's own base, here too
        f = Fleet(str(tmp_path_factory.mktemp("fleet-yamcs")))
        try:
            yield f
        finally:
            f.close()


def test_each_instance_receives_its_own_spacecrafts_housekeeping(ground):
    for name in ground.names:
        pv = ground.values[name].wait(lambda v, n=name: v.name == "/%s/SolarPanel/angle" % n)
        assert pv.eng_value is not None
        link = ground.client.get_link(name, "pus").get_info()
        assert link.status == "OK" and link.in_count > 0


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
        for stage in ("Verifier_Accepted", "Verifier_Started", "Verifier_Complete"):
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


def test_a_ping_to_each_instance_completes_through_service_1(ground):
    for name in ground.names:
        cmd = ground.issue(name, "PUS/ping")
        assert cmd.is_success(), (name, cmd.error)
        assert cmd.acknowledgments["Verifier_Complete"].status == "OK"
