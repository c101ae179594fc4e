"""A real Yamcs server commanding the sample spacecraft, once per test session.

One Yamcs process runs two instances on one generated configuration: ``packets`` (PUS packets
over the packet gateway) and ``frames`` (TC frames in CLTUs with Yamcs' COP-1 FOP against our
FARM-1 through the frame processor, TM frames with the CLCW). Each instance talks to its own
sample spacecraft in this process. Without Java or the Yamcs jars every test here is skipped
with the reason.
"""

import hashlib
import os
import socket
import threading
import time

import pytest
from obsw_host.pus.demo import SDB_PATH
from obsw_host.yamcs import database, instance, server
from obsw_host.yamcs.spacecraft import SampleSpacecraft

MISSING = server.missing()
pytestmark = pytest.mark.skipif(MISSING is not None, reason=str(MISSING))
MISSION = "/obsw-demo"
TIMEOUT = 30.0


def free_port(kind=socket.SOCK_STREAM):
    s = socket.socket(socket.AF_INET, kind)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


class Drop:
    """Loses the next ``n`` CLTUs on the way to the frame processor."""

    def __init__(self):
        self.n = 0
        self.lost = 0

    def __call__(self, data):
        if self.n > 0:
            self.n -= 1
            self.lost += 1
            return True
        return False


class Ground:
    """The Yamcs server and both sample spacecraft."""

    def __init__(self, folder):
        from yamcs.client import YamcsClient

        self.folder = folder
        self.drop = Drop()
        self.sats = {}
        self.sats["packets"] = SampleSpacecraft(SDB_PATH, os.path.join(folder, "sat-p"))
        tm_frames = free_port(socket.SOCK_DGRAM)
        self.sats["frames"] = SampleSpacecraft(
            SDB_PATH,
            os.path.join(folder, "sat-f"),
            "frames",
            tm_frames_port=tm_frames,
            drop=self.drop,
        )
        frames_ports = dict(self.sats["frames"].ports(), tm_frames=tm_frames)
        self.http_port = free_port()
        instance.write_instance(
            folder,
            database.load(SDB_PATH),
            http_port=self.http_port,
            instances={
                "packets": ("packets", self.sats["packets"].ports()),
                "frames": ("frames", frames_ports),
            },
        )
        for sat in self.sats.values():
            sat.start()
        self.yamcs = server.Yamcs(folder, self.http_port, instance="frames")
        started = time.monotonic()
        self.yamcs.start(timeout=90)
        self.startup = time.monotonic() - started
        self.client = YamcsClient("127.0.0.1:%d" % self.http_port)
        self.connections = {}
        self.cop1 = self.client.get_link("frames", "tc_frames.vc0")
        self.initialize_cop1()

    def initialize_cop1(self):
        """Initialise AD with a CLCW check, as an operator would, and wait for 'active'."""
        active = threading.Event()

        def on_status(status):
            if status.state == "ACTIVE":
                active.set()

        sub = self.cop1.create_cop1_subscription(on_status)
        try:
            self.cop1.initialize_cop1("WITH_CLCW_CHECK", clcw_wait_timeout=10)
            assert active.wait(TIMEOUT), "COP-1 did not become active"
        finally:
            sub.cancel()

    def processor(self, name):
        return self.client.get_processor(name, "realtime")

    def connection(self, name):
        """One command connection per instance, following each command's acknowledgments."""
        conn = self.connections.get(name)
        if conn is None:
            conn = self.connections[name] = self.processor(name).create_command_connection()
        return conn

    def close(self):
        for conn in self.connections.values():
            conn.cancel()
        self.yamcs.stop()
        for sat in self.sats.values():
            sat.close()


@pytest.fixture(scope="session")
def ground(tmp_path_factory):
    g = Ground(str(tmp_path_factory.mktemp("yamcs")))
    print("Yamcs started in %.1f s" % g.startup)
    yield g
    g.close()


MODES = ["packets", "frames"]


def wait_value(processor, name, predicate, timeout=TIMEOUT):
    """The first value of parameter ``name`` Yamcs publishes for which ``predicate`` holds."""
    found = []
    done = threading.Event()

    def on_data(data):
        for pv in data.parameters:
            if pv.name == name and predicate(pv.eng_value):
                found.append(pv)
                done.set()

    sub = processor.create_parameter_subscription([name], on_data=on_data)
    try:
        assert done.wait(timeout), "no value of %s satisfying the check" % name
    finally:
        sub.cancel()
    return found[0]


def issue(ground, mode, command, args=None):
    cmd = ground.connection(mode).issue(command, args=args)
    cmd.await_complete(timeout=TIMEOUT)
    return cmd


def verifiers(cmd):
    acks = cmd.acknowledgments
    return {k: acks[k].status for k in ("Verifier_Accepted", "Verifier_Started") if k in acks}


@pytest.mark.parametrize("mode", MODES)
def test_housekeeping_decoded_as_sent(ground, mode):
    panel = ground.sats[mode].panel
    proc = ground.processor(mode)
    for attr, name in (("angle", "angle"), ("speed", "speed"), ("is_deployed", "is_deployed")):
        expected = getattr(panel, attr)
        pv = wait_value(proc, "%s/SolarPanel/%s" % (MISSION, name), lambda v, e=expected: v == e)
        assert pv.eng_value == expected


@pytest.mark.parametrize("mode", MODES)
def test_ping_completes_through_service_1(ground, mode):
    cmd = issue(ground, mode, MISSION + "/PUS/ping")
    assert cmd.is_success(), cmd.error
    assert verifiers(cmd) == {"Verifier_Accepted": "OK", "Verifier_Started": "OK"}


@pytest.mark.parametrize("mode", MODES)
def test_parameter_set_completes_and_reaches_the_panel(ground, mode):
    value = {"packets": 7.5, "frames": 8.5}[mode]
    cmd = issue(ground, mode, MISSION + "/SolarPanel/set_speed", {"value": value})
    assert cmd.is_success(), cmd.error
    assert ground.sats[mode].panel.speed == value
    wait_value(ground.processor(mode), MISSION + "/SolarPanel/speed", lambda v: v == value)


def test_out_of_range_and_refused_commands(ground):
    # Yamcs checks the database's range before sending; the panel's own refusal comes back
    # as a service 1 completion failure with its failure code
    with pytest.raises(Exception, match="range|Range|bound"):
        issue(ground, "packets", MISSION + "/SolarPanel/set_speed", {"value": 50.0})
    cmd = issue(ground, "packets", MISSION + "/SolarPanel/set_angle", {"angle": 1000.0})
    assert cmd.is_failure()
    assert cmd.acknowledgments["Verifier_Accepted"].status == "OK"
    assert "component_error" in cmd.error


@pytest.mark.parametrize("mode", MODES)
def test_events_with_severity_from_functions(ground, mode):
    events = []
    got = threading.Event()

    def on_event(e):
        events.append(e)
        if "SolarPanel.angle_reached" in (e.message or ""):
            got.set()

    sub = ground.client.create_event_subscription(mode, on_data=on_event)
    try:
        cmd = issue(ground, mode, MISSION + "/SolarPanel/deploy")
        assert cmd.is_success(), cmd.error
        cmd = issue(ground, mode, MISSION + "/SolarPanel/set_angle", {"angle": 12.5})
        assert cmd.is_success(), cmd.error
        assert got.wait(TIMEOUT)
    finally:
        sub.cancel()
    by_text = {e.message.split(":")[0]: e for e in events if e.message}
    assert by_text["SolarPanel.deployed"].severity == "WATCH"
    assert "hinges=3" in by_text["SolarPanel.deployed"].message
    assert by_text["SolarPanel.angle_reached"].severity == "INFO"
    assert "angle=12.5" in by_text["SolarPanel.angle_reached"].message


def test_limit_violation_raises_an_alarm(ground):
    proc = ground.processor("packets")
    cmd = issue(ground, "packets", MISSION + "/SolarPanel/set_speed", {"value": 12.0})
    assert cmd.is_success(), cmd.error
    pv = wait_value(proc, MISSION + "/SolarPanel/speed", lambda v: v == 12.0)
    assert pv.monitoring_result == "WARNING"
    names = [a.name for a in proc.list_alarms()]
    assert MISSION + "/SolarPanel/speed" in names
    issue(ground, "packets", MISSION + "/SolarPanel/set_speed", {"value": 5.0})


def _file(path, size, seed):
    data = hashlib.sha256(seed.encode()).digest() * (size // 32 + 1)
    with open(path, "wb") as f:
        f.write(data[:size])
    return data[:size]


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("reliable", [False, True], ids=["class1", "class2"])
def test_cfdp_upload_from_yamcs(ground, mode, reliable):
    name = "up-%s-%d.bin" % (mode, reliable)
    data = _file(os.path.join(ground.folder, "files", mode, "up", name), 5000, name)
    service = ground.client.get_file_transfer_client(mode).get_service("cfdp0")
    tx = service.upload(mode + "_up", name, name, options={"reliable": reliable})
    tx.await_complete(timeout=TIMEOUT)
    assert tx.is_success(), tx.error
    sat = ground.sats[mode]
    assert sat.wait_finished(role="R", timeout=TIMEOUT) is not None
    with open(os.path.join(sat.root, name), "rb") as f:
        assert f.read() == data


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("reliable", [False, True], ids=["class1", "class2"])
def test_cfdp_download_to_yamcs(ground, mode, reliable):
    sat = ground.sats[mode]
    name = "down-%s-%d.bin" % (mode, reliable)
    data = _file(os.path.join(sat.root, name), 7000, name)
    service = ground.client.get_file_transfer_client(mode).get_service("cfdp0")
    completed = threading.Event()

    def on_transfer(t):
        if t.remote_path.endswith(name) and t.state == "COMPLETED":
            completed.set()

    sub = service.create_transfer_subscription(on_data=on_transfer)
    try:
        tid = sat.put(name, mode=1 if reliable else 0)  # 1: acknowledged (class 2)
        assert sat.wait_finished(tid, "S", timeout=TIMEOUT) is not None
        assert completed.wait(TIMEOUT), "Yamcs did not complete the transfer"
    finally:
        sub.cancel()
    path = os.path.join(ground.folder, "files", mode, "down", name)
    with open(path, "rb") as f:
        assert f.read() == data


def test_lost_frame_is_retransmitted_by_cop1(ground):
    before = ground.drop.lost
    ground.drop.n = 1
    cmd = issue(ground, "frames", MISSION + "/PUS/ping")
    assert cmd.is_success(), cmd.error
    assert ground.drop.lost == before + 1
    counters = ground.sats["frames"].processor.core.counters
    assert counters["accepted"] >= 1
