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
from obsw_host.sample import SDB_PATH
from obsw_host.yamcs import database, instance, server
from obsw_host.yamcs.spacecraft import SampleSpacecraft

MISSING = server.missing()
pytestmark = pytest.mark.skipif(MISSING is not None, reason=str(MISSING))
MISSION = "/obsw-demo"
XTCE = {"x": "http://www.omg.org/spec/XTCE/20180204"}
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


class Watch:
    """Everything one long-lived subscription delivers, with a wait for a matching item.

    (Subscriptions stay open for the session: closing a websocket subscription can take the
    client library seconds.)"""

    def __init__(self):
        self.items = []
        self.changed = threading.Condition()

    def __call__(self, item):
        with self.changed:
            self.items.append(item)
            self.changed.notify_all()

    def wait(self, predicate, since=0, timeout=TIMEOUT):
        """The first item from index ``since`` on for which ``predicate`` holds."""

        def find():
            for item in self.items[since:]:
                if predicate(item):
                    return item
            return None

        with self.changed:
            self.changed.wait_for(lambda: find() is not None, timeout)
            found = find()
        assert found is not None, "nothing matching came within %ss" % timeout
        return found

    def mark(self):
        return len(self.items)


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
        try:
            self.yamcs.start(timeout=90)
        except server.YamcsUnavailable as e:
            self.close()
            pytest.skip(str(e))
        self.startup = time.monotonic() - started
        self.client = YamcsClient("127.0.0.1:%d" % self.http_port)
        self.connections = {}
        self.cop1 = self.client.get_link("frames", "tc_frames.vc0")
        self.initialize_cop1()
        self.values = {}
        self.events = {}
        self.transfers = {}
        self.subscriptions = []
        for mode in ("packets", "frames"):
            self.values[mode] = w = Watch()

            def on_values(data, w=w):
                for pv in data.parameters:
                    w(pv)

            names = [
                MISSION + "/SolarPanel/" + n
                for n in ("angle", "speed", "is_deployed", "speed_check_state")
            ]
            self.subscriptions.append(
                self.processor(mode).create_parameter_subscription(names, on_data=on_values)
            )
            self.events[mode] = Watch()
            self.subscriptions.append(
                self.client.create_event_subscription(mode, on_data=self.events[mode])
            )
            self.transfers[mode] = Watch()
            service = self.client.get_file_transfer_client(mode).get_service("cfdp0")
            self.subscriptions.append(
                service.create_transfer_subscription(on_data=self.transfers[mode])
            )

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
        self.yamcs.stop()  # ends the client's subscriptions too
        for sat in self.sats.values():
            sat.close()


@pytest.fixture(scope="session")
def ground(tmp_path_factory):
    g = Ground(str(tmp_path_factory.mktemp("yamcs")))
    print("Yamcs started in %.1f s" % g.startup)
    yield g
    g.close()


MODES = ["packets", "frames"]


def wait_value(ground, mode, name, predicate, since=0):
    """The first value of parameter ``name`` Yamcs published for which ``predicate`` holds."""
    return ground.values[mode].wait(lambda pv: pv.name == name and predicate(pv.eng_value), since)


def issue(ground, mode, command, args=None):
    cmd = ground.connection(mode).issue(command, args=args)
    cmd.await_complete(timeout=TIMEOUT)
    # Yamcs may conclude a command on its completion report before it has marked the
    # acceptance report that came first (their times can be equal): wait for that mark too
    cmd.await_acknowledgment("Verifier_Accepted", timeout=TIMEOUT)
    return cmd


def verifiers(cmd):
    acks = cmd.acknowledgments
    return {k: acks[k].status for k in ("Verifier_Accepted", "Verifier_Started") if k in acks}


@pytest.mark.parametrize("mode", MODES)
def test_housekeeping_decoded_as_sent(ground, mode):
    panel = ground.sats[mode].panel
    for name in ("angle", "speed", "is_deployed"):
        expected = getattr(panel, name)
        pv = wait_value(ground, mode, "%s/SolarPanel/%s" % (MISSION, name), lambda v: True)
        assert pv.eng_value == expected
        assert pv.generation_time is not None


@pytest.mark.parametrize("mode", MODES)
def test_ping_completes_through_service_1(ground, mode):
    cmd = issue(ground, mode, MISSION + "/PUS/ping")
    assert cmd.is_success(), cmd.error
    assert verifiers(cmd) == {"Verifier_Accepted": "OK", "Verifier_Started": "OK"}


@pytest.mark.parametrize("mode", MODES)
def test_parameter_set_completes_and_reaches_the_panel(ground, mode):
    value = {"packets": 7.5, "frames": 8.5}[mode]
    mark = ground.values[mode].mark()
    cmd = issue(ground, mode, MISSION + "/SolarPanel/set_speed", {"value": value})
    assert cmd.is_success(), cmd.error
    assert verifiers(cmd) == {"Verifier_Accepted": "OK", "Verifier_Started": "OK"}
    assert ground.sats[mode].panel.speed == value
    wait_value(ground, mode, MISSION + "/SolarPanel/speed", lambda v: v == value, mark)


def test_out_of_range_and_refused_commands(ground):
    # Yamcs checks the database's range before sending; the panel's own refusal comes back
    # as a service 1 completion failure with its failure code and data
    with pytest.raises(Exception, match="range|Range|bound"):
        issue(ground, "packets", MISSION + "/SolarPanel/set_speed", {"value": 50.0})
    cmd = issue(ground, "packets", MISSION + "/SolarPanel/set_angle", {"angle": 1000.0})
    assert cmd.is_failure()
    assert cmd.acknowledgments["Verifier_Accepted"].status == "OK"
    assert "component_error" in cmd.error
    # with the failure's data: the component's error, NOT_DEPLOYED, among it
    assert b"NOT_DEPLOYED".hex().upper() in cmd.error


@pytest.mark.parametrize("mode", MODES)
def test_events_with_severity_from_functions(ground, mode):
    events = ground.events[mode]
    mark = events.mark()
    cmd = issue(ground, mode, MISSION + "/SolarPanel/deploy")
    assert cmd.is_success(), cmd.error
    cmd = issue(ground, mode, MISSION + "/SolarPanel/set_angle", {"angle": 12.5})
    assert cmd.is_success(), cmd.error
    deployed = events.wait(lambda e: (e.message or "").startswith("SolarPanel.deployed"), mark)
    reached = events.wait(lambda e: (e.message or "").startswith("SolarPanel.angle_"), mark)
    assert deployed.severity == "WATCH"  # a low severity event, TM[5,2]
    assert "hinges=3" in deployed.message
    assert reached.severity == "INFO"  # TM[5,1]
    assert "angle=12.5" in reached.message


def test_limit_violation_raises_an_alarm(ground):
    proc = ground.processor("packets")
    mark = ground.values["packets"].mark()
    cmd = issue(ground, "packets", MISSION + "/SolarPanel/set_speed", {"value": 12.0})
    assert cmd.is_success(), cmd.error
    pv = wait_value(ground, "packets", MISSION + "/SolarPanel/speed", lambda v: v == 12.0, mark)
    assert pv.monitoring_result == "WARNING"  # the database's warning range is 1..10
    names = [a.name for a in proc.list_alarms()]
    assert MISSION + "/SolarPanel/speed" in names
    assert issue(ground, "packets", MISSION + "/SolarPanel/set_speed", {"value": 5.0}).is_success()


def test_service_12_transition_raises_an_alarm(ground):
    # a limit check defined from Yamcs with the database's critical range (0.5..15); the
    # OBC's check transition report (TM[12,12]) sets the checking state, which Yamcs alarms
    proc = ground.processor("packets")
    assert issue(
        ground, "packets", MISSION + "/SolarPanel/monitor_speed", {"pmon": 7}
    ).is_success()
    assert issue(ground, "packets", MISSION + "/PUS/monitor_enable", {"pmon": 7}).is_success()
    mark = ground.values["packets"].mark()
    cmd = issue(ground, "packets", MISSION + "/SolarPanel/set_speed", {"value": 16.0})
    assert cmd.is_success(), cmd.error
    state = MISSION + "/SolarPanel/speed_check_state"
    pv = wait_value(ground, "packets", state, lambda v: v == "above_high", mark)
    assert pv.monitoring_result == "CRITICAL"
    assert state in [a.name for a in proc.list_alarms()]
    assert issue(ground, "packets", MISSION + "/SolarPanel/set_speed", {"value": 5.0}).is_success()
    wait_value(ground, "packets", state, lambda v: v == "within", mark)
    assert issue(ground, "packets", MISSION + "/PUS/monitor_disable", {"pmon": 7}).is_success()


def _file(path, size, seed):
    data = hashlib.sha256(seed.encode()).digest() * (size // 32 + 1)
    with open(path, "wb") as f:
        f.write(data[:size])
    return data[:size]


def _bucket_file(path, size, timeout=TIMEOUT):
    """The file Yamcs stored in a bucket. Yamcs may announce a received transfer complete a
    moment before the file is in the bucket, or while it is still writing it, and offers no
    notification for that, so this one place polls the folder until the file has ``size``
    octets (at most ``timeout`` s)."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if os.path.exists(path) and os.path.getsize(path) >= size:
            break
        time.sleep(0.02)
    with open(path, "rb") as f:
        return f.read()


def _transfer_done(name):
    return lambda t: t.remote_path.endswith(name) and t.state in ("COMPLETED", "FAILED")


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("reliable", [False, True], ids=["class1", "class2"])
def test_cfdp_upload_from_yamcs(ground, mode, reliable):
    sat = ground.sats[mode]
    name = "up-%s-%d.bin" % (mode, reliable)
    data = _file(os.path.join(ground.folder, "files", mode, "up", name), 5000, name)
    received = len(sat.finished(role="R"))
    mark = ground.transfers[mode].mark()
    service = ground.client.get_file_transfer_client(mode).get_service("cfdp0")
    service.upload(mode + "_up", name, name, options={"reliable": reliable})
    tx = ground.transfers[mode].wait(_transfer_done(name), mark)
    assert tx.state == "COMPLETED", tx.error
    assert sat.wait_finished(role="R", count=received + 1, timeout=TIMEOUT) is not None
    with open(os.path.join(sat.root, name), "rb") as f:
        assert f.read() == data


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("reliable", [False, True], ids=["class1", "class2"])
def test_cfdp_download_to_yamcs(ground, mode, reliable):
    sat = ground.sats[mode]
    name = "down-%s-%d.bin" % (mode, reliable)
    data = _file(os.path.join(sat.root, name), 7000, name)
    mark = ground.transfers[mode].mark()
    tid = sat.put(name, mode=1 if reliable else 0)  # 1: acknowledged (class 2)
    assert sat.wait_finished(tid, "S", timeout=TIMEOUT) is not None
    tx = ground.transfers[mode].wait(_transfer_done(name), mark)
    assert tx.state == "COMPLETED", tx.error
    path = os.path.join(ground.folder, "files", mode, "down", name)
    assert _bucket_file(path, len(data)) == data


def test_lost_frame_is_retransmitted_by_cop1(ground):
    counters = ground.sats["frames"].processor.core.counters
    accepted = counters["accepted"]
    before = ground.drop.lost
    ground.drop.n = 1  # the next CLTU never reaches the frame processor
    cmd = issue(ground, "frames", MISSION + "/PUS/ping")
    assert cmd.is_success(), cmd.error
    assert ground.drop.lost == before + 1
    assert counters["accepted"] == accepted + 1  # the retransmitted frame, once


def _socket_inodes(pid):
    inodes = set()
    fd_dir = "/proc/%d/fd" % pid
    for fd in os.listdir(fd_dir):
        try:
            target = os.readlink(os.path.join(fd_dir, fd))
        except OSError:
            continue
        if target.startswith("socket:["):
            inodes.add(target[8:-1])
    return inodes


def test_yamcs_listens_on_loopback_only(ground):
    if not os.path.exists("/proc/net/udp"):
        pytest.skip("no /proc/net to inspect sockets on this system")
    inodes = _socket_inodes(ground.yamcs.process.pid)
    loopback = ("0100007F", "00000000000000000000000001000000")
    listening = []
    for table, listen_state in (("tcp", "0A"), ("tcp6", "0A"), ("udp", None), ("udp6", None)):
        with open("/proc/net/" + table) as f:
            for row in f.read().splitlines()[1:]:
                cols = row.split()
                if cols[9] in inodes and (listen_state is None or cols[3] == listen_state):
                    listening.append((table, cols[1]))
    assert listening, "found none of Yamcs' sockets"
    assert [x for x in listening if x[1].split(":")[0] not in loopback] == []


def _expected_parameters(root, name, keys):
    """The parameters a report of ``name`` fills: its own (those without an alias), and for
    each alias name space its containers select in, the parameter of the sample's selector."""
    systems, aliases = {}, {}

    def walk(ss, path):
        path = path + "/" + ss.get("name")
        systems[path] = ss
        for p in ss.findall("x:TelemetryMetaData/x:ParameterSet/x:Parameter", XTCE):
            for a in p.findall("x:AliasSet/x:Alias", XTCE):
                aliases[(a.get("nameSpace"), a.get("alias"))] = path + "/" + p.get("name")
        for child in ss.findall("x:SpaceSystem", XTCE):
            walk(child, path)

    walk(root, "")
    report = systems[MISSION + "/TM/" + name]
    own = [
        MISSION + "/TM/" + name + "/" + p.get("name")
        for p in report.findall("x:TelemetryMetaData/x:ParameterSet/x:Parameter", XTCE)
        if p.find("x:AliasSet", XTCE) is None
    ]
    for entry in report.iter("{%s}IndirectParameterRefEntry" % XTCE["x"]):
        space = entry.get("aliasNameSpace")
        own.append(aliases[(space, str(keys["type" if "obcp" in name else "pid"]))])
    refs = report.iter("{%s}ContainerRefEntry" % XTCE["x"])
    if any(e.get("containerRef").endswith("/embedded_tc") for e in refs):
        tc = systems[MISSION + "/TM/embedded_tc"]
        own += [
            MISSION + "/TM/embedded_tc/" + p.get("name")
            for p in tc.findall("x:TelemetryMetaData/x:ParameterSet/x:Parameter", XTCE)
        ]
    return sorted(set(own))


def test_every_report_is_decoded(ground):
    """Each report of every layout the OBC packs (obsw_host.yamcs.report_layouts), with every
    repeated group twice and every service 12 check type once, sent to Yamcs: every parameter
    of the report gets its value (test_yamcs_reports checks the list covers the service
    tables)."""
    import sys
    import xml.etree.ElementTree as ET

    from obsw.pus.config import from_sdb
    from obsw.pus.fields import field
    from obsw.pus.sdb import load as load_sdb
    from obsw.pus.services import s18_layouts
    from obsw.pus.tm import PusTm
    from obsw_host.yamcs import xtce
    from obsw_host.yamcs.report_layouts import report_layouts

    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from report_samples import Sampler

    sc = database.load(SDB_PATH)
    config = from_sdb(load_sdb(SDB_PATH))
    apid = load_sdb(SDB_PATH).apid("pus")
    root = ET.fromstring(xtce.generate(sc))
    sampler = Sampler(1, config, apid)
    keys = {"pid": 1, "type": s18_layouts.ARG_INT}
    sat = ground.sats["packets"]
    proc = ground.processor("packets")
    out = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    undecoded = {}
    try:
        for n, (msg_type, (name, layout)) in enumerate(
            sorted(report_layouts(lambda pid: field(*sc.params[pid].pair)).items())
        ):
            data = layout.pack(sampler.layout(layout))
            tm = PusTm(apid, msg_type[0], msg_type[1], data, seq_count=n, time=(1000, 0),
                       config=config)  # fmt: skip
            out.sendto(tm.pack(), sat.gateway.tm_address)
            names = _expected_parameters(root, name, keys)
            deadline = time.monotonic() + 10.0
            while True:
                values = proc.get_parameter_values(names)
                missing = [nm for nm, v in zip(names, values) if v is None]
                if not missing or time.monotonic() > deadline:
                    break
                time.sleep(0.2)
            if missing:
                undecoded["%s %s" % (msg_type, name)] = missing
    finally:
        out.close()
    assert not undecoded
