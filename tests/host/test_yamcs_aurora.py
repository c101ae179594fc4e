"""Yamcs operating a second mission, `examples/aurora`, as a team would run it: `obsw obc serve`
of the mission folder (its own processes, its Magnetorquer plug-in, APID 42, CDS time) and
`obsw yamcs run --mission aurora --obc HOST:PORT`, then Yamcs' own client: commands from the
generated database completing through service 1 (a function of the plug-in, a request of the
mission's own service 140), calibrated values in engineering units with their limits, the
component's event, and a CFDP upload into the OBC's filestore. Skipped with the reason without
Java or the Yamcs jars."""

import hashlib
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time

import pytest
from obsw_host.mission.ids import MissionIds
from obsw_host.update import build as update_build
from obsw_host.yamcs import server
from obsw_host.yamcs.instance import instance_name
from test_yamcs_e2e import Watch

MISSING = server.missing()
pytestmark = pytest.mark.skipif(MISSING is not None, reason=str(MISSING))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OBSW = [sys.executable, "-m", "obsw_host.cli"]
TIMEOUT = 30.0


def free_ports(n, kind=socket.SOCK_DGRAM):
    socks = [socket.socket(socket.AF_INET, kind) for _ in range(n)]
    for s in socks:
        s.bind(("127.0.0.1", 0))
    ports = [s.getsockname()[1] for s in socks]
    for s in socks:
        s.close()
    return ports


def free_base():
    """A port base B with the mission's PUS and CFDP ports (B + APID) free."""
    for base in range(31000, 60000, 211):
        try:
            for offset in (42, 300, 301):
                s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
                try:
                    s.bind(("127.0.0.1", base + offset))
                finally:
                    s.close()
        except OSError:
            continue
        return base
    raise RuntimeError("no free port base")


class Lines:
    """A process's output lines as they come, with a wait for one."""

    def __init__(self, stream):
        self.lines = []
        self.changed = threading.Condition()
        threading.Thread(target=self._read, args=(stream,), daemon=True).start()

    def _read(self, stream):
        for line in stream:
            with self.changed:
                self.lines.append(line.rstrip("\n"))
                self.changed.notify_all()

    def until(self, predicate, timeout=90.0):
        with self.changed:
            self.changed.wait_for(lambda: any(predicate(x) for x in self.lines), timeout)
            found = [x for x in self.lines if predicate(x)]
        assert found, "not seen within %ss:\n%s" % (timeout, "\n".join(self.lines[-30:]))
        return found[0]


def _start(argv, env, cwd):
    proc = subprocess.Popen(
        argv,
        env=env,
        cwd=cwd,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,  # its children stop with it
    )
    return proc, Lines(proc.stdout)


def _stop(proc):
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGTERM)
        try:
            proc.wait(30)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()


class Aurora:
    def __init__(self, work):
        from yamcs.client import YamcsClient

        self.work = work
        folder = os.path.join(work, "aurora")
        shutil.copytree(os.path.join(ROOT, "examples", "aurora"), folder)
        # the ground's update key, its public half in the mission (test_update_through_yamcs)
        self.update_key = os.path.join(work, "update.key")
        update_build.keygen(self.update_key, allow_git=True)
        shutil.copy(self.update_key + ".pub", os.path.join(folder, "update.pub"))
        with open(os.path.join(folder, "mission.json")) as f:
            doc = json.load(f)
        doc["update"] = {"public_key": "update.pub", "healthy_after": 1.0}
        with open(os.path.join(folder, "mission.json"), "w") as f:
            json.dump(doc, f, indent=2)
        self.env = dict(
            os.environ,
            OBSW_PORT_BASE=str(free_base()),
            OBSW_STATE=os.path.join(work, "state"),
            OBSW_MISSION=os.path.join(work, "aurora"),
        )
        self.procs = []
        obc, out = _start(OBSW + ["obc", "serve", "aurora"], self.env, work)
        self.procs.append(obc)
        out.until(lambda x: "up: components" in x)  # the last of its three processes
        out.until(lambda x: x.startswith("PUS application process"))
        self.ids = MissionIds.locate(os.path.join(work, "aurora"))
        pus = int(out.until(lambda x: x.startswith("PUS application process")).split(":")[-1]
                  .split(",")[0])  # fmt: skip
        self.filestore = os.path.join(work, "state", self.ids.name, "files")
        self.instance = instance_name(self.ids.name)
        self.http, yamcs_pus, yamcs_cfdp = free_ports(3, socket.SOCK_STREAM)
        argv = ["yamcs", "run", "--obc", "127.0.0.1:%d" % pus, "--dir", os.path.join(work, "y")]
        argv += ["--http-port", str(self.http), "--pus-port", str(yamcs_pus)]
        argv += ["--cfdp-port", str(yamcs_cfdp), "--mission", "aurora"]
        yamcs, self.yamcs_out = _start(OBSW + argv, self.env, work)
        self.procs.append(yamcs)
        t0 = time.monotonic()
        self.yamcs_out.until(lambda x: x.startswith("Yamcs ") and " on http" in x, 150)
        self.startup = time.monotonic() - t0
        self.client = YamcsClient("127.0.0.1:%d" % self.http)
        self.processor = self.client.get_processor(self.instance, "realtime")
        self.values, self.events, self.transfers = Watch(), Watch(), Watch()

        def on_values(data):
            for pv in data.parameters:
                self.values(pv)

        names = ["/%s/Magnetorquer/%s" % (self.instance, n) for n in ("coil_temp", "dipole_x")]
        self.subscriptions = [
            self.processor.create_parameter_subscription(names, on_data=on_values),
            self.client.create_event_subscription(self.instance, on_data=self.events),
        ]
        files = self.client.get_file_transfer_client(self.instance).get_service("cfdp0")
        self.cfdp = files
        self.subscriptions.append(files.create_transfer_subscription(on_data=self.transfers))

    def issue(self, name, args=None):
        # a command connection of its own (a websocket) per command: a long-lived one was
        # found closed under load after the long CFDP upload, its completion never heard
        commands = self.processor.create_command_connection()
        try:
            cmd = commands.issue("/%s/%s" % (self.instance, name), args=args)
            cmd.await_complete(timeout=TIMEOUT)
            # Yamcs may conclude a command on its completion report before it has marked the
            # acceptance report that came first (their times can be equal): wait for that mark
            # too while the connection still follows the command
            cmd.await_acknowledgment("Verifier_Accepted", timeout=TIMEOUT)
        finally:
            commands.cancel()  # its websocket closed
        return cmd

    def close(self):
        for proc in reversed(self.procs):
            _stop(proc)


@pytest.fixture(scope="module")
def aurora(tmp_path_factory):
    a = Aurora(str(tmp_path_factory.mktemp("aurora")))
    print("aurora: Yamcs started in %.1f s" % a.startup)
    yield a
    a.close()


def test_commands_from_the_generated_database_complete_through_service_1(aurora):
    for name in ("PUS/ping", "Magnetorquer/degauss"):
        cmd = aurora.issue(name)
        assert cmd.is_success(), (name, cmd.error)
        acks = cmd.acknowledgments
        assert acks["Verifier_Accepted"].status == "OK" and acks["Verifier_Started"].status == "OK"


def test_calibrated_values_in_engineering_units_within_their_limits(aurora):
    # raw thermistor counts through the database's spline: about 21 degC, inside -10..60
    pv = aurora.values.wait(lambda v: v.name.endswith("/coil_temp") and v.eng_value is not None)
    raw_at_0, raw_at_100 = 1365, 1765
    assert pv.eng_value == pytest.approx(
        100.0 * (pv.raw_value - raw_at_0) / (raw_at_100 - raw_at_0)
    )
    assert pv.monitoring_result == "IN_LIMITS"
    mdb = aurora.client.get_mdb(aurora.instance)
    assert mdb.get_parameter("/%s/Magnetorquer/coil_temp" % aurora.instance).units == ["degC"]


def test_the_mission_service_from_yamcs_reaches_the_plug_in(aurora):
    dipole = {"x": 0.05, "y": 0.0, "z": 0.0}
    cmd = aurora.issue("mtq/dipole", dipole)  # TC[140,1]: the plug-in refuses while disabled
    assert cmd.is_failure() and "component_error" in cmd.error
    assert cmd.acknowledgments["Verifier_Accepted"].status == "OK"
    assert aurora.issue("Magnetorquer/enable").is_success()
    cmd = aurora.issue("mtq/dipole", dipole)
    assert cmd.is_success(), cmd.error
    pv = aurora.values.wait(
        lambda v: v.name.endswith("/dipole_x") and v.eng_value == pytest.approx(0.05, abs=1e-6)
    )
    assert pv.monitoring_result == "IN_LIMITS"
    with pytest.raises(Exception, match="range|Range|bound"):  # Yamcs checks the database's
        aurora.issue("mtq/dipole", {"x": 0.5, "y": 0.0, "z": 0.0})


def test_the_plug_ins_event_with_its_data(aurora):
    assert aurora.issue("Magnetorquer/degauss").is_success()
    event = aurora.events.wait(lambda e: "Magnetorquer.degaussed" in (e.message or ""))
    assert "cycles=" in event.message


def test_cfdp_upload_into_the_obcs_filestore(aurora):
    name = "tle-upload.bin"
    data = hashlib.sha256(name.encode()).digest() * 200
    up = os.path.join(aurora.work, "y", "files", aurora.instance, "up")
    os.makedirs(up, exist_ok=True)
    with open(os.path.join(up, name), "wb") as f:
        f.write(data)
    aurora.cfdp.upload(aurora.instance + "_up", name, name, options={"reliable": True})
    tx = aurora.transfers.wait(
        lambda t: t.remote_path.endswith(name) and t.state in ("COMPLETED", "FAILED")
    )
    assert tx.state == "COMPLETED", tx.error
    with open(os.path.join(aurora.filestore, name), "rb") as f:
        assert f.read() == data


def test_an_update_through_yamcs(aurora):
    """A package goes up with Yamcs' CFDP service into the OBC's update folder; Yamcs commands
    from the generated database stage and activate it; the platform manager confirms it."""
    name = "aurora-1.1.obsw"
    up = os.path.join(aurora.work, "y", "files", aurora.instance, "up")
    os.makedirs(up, exist_ok=True)
    folder = os.path.join(aurora.work, "aurora")
    update_build.build(os.path.join(up, name), update_build.sources(folder),
                       mission=aurora.ids.name, version="1.1",
                       key=update_build.load_private(aurora.update_key))  # fmt: skip
    aurora.cfdp.upload(aurora.instance + "_up", name, "update/" + name, options={"reliable": True})
    tx = aurora.transfers.wait(
        lambda t: t.remote_path.endswith(name) and t.state in ("COMPLETED", "FAILED")
    )
    assert tx.state == "COMPLETED", tx.error
    cmd = aurora.issue("Software/stage", {"file": "update/" + name})
    assert cmd.is_success(), cmd.error
    record = os.path.join(aurora.work, "state", aurora.ids.name, "software", "boot.json")
    with open(record) as f:
        assert json.load(f)["staged"] == "a"
    assert aurora.issue("Software/activate").is_success()
    deadline = time.monotonic() + 90
    while time.monotonic() < deadline:
        with open(record) as f:
            if json.load(f)["active"] == "a":
                break
        time.sleep(0.2)
    with open(record) as f:
        done = json.load(f)
    assert done["active"] == "a" and done["log"][-1]["event"] == "confirmed", done
