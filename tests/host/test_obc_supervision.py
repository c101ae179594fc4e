"""The OBC's supervision chain, piece by piece: the Linux watchdog device interface on a
simulated device, systemd's notify protocol on a fake socket, the rule that feeds the
watchdog only while every critical process is healthy, the health figures from a simulated
/proc and /sys tree, and the systemd unit. Clocks are simulated where time matters."""

import json
import math
import os
import shutil
import socket
import subprocess
import sys
import time

import pytest
from obsw.il.clock import SimClock
from obsw.pus.app import ApplicationProcess
from obsw.pus.parameters import ParameterPool
from obsw.pus.services.s12_monitoring import OnBoardMonitoring
from obsw_host.mission.config import ConfigError
from obsw_host.obc import monitoring
from obsw_host.obc import watchdog as wd
from obsw_host.obc.health import HostHealth, ObcHealth
from obsw_host.obc.sdnotify import Notifier
from obsw_host.obc.service import DEFAULTS, unit_text
from obsw_host.obc.supervision import Supervision
from obsw_host.sample import load_sdb
from obsw_sim.watchdog import SimulatedWatchdog

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OBSW = os.path.join(os.path.dirname(sys.executable), "obsw")


def wait_for(predicate, timeout=10.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if predicate():
            return True
        time.sleep(0.01)
    return predicate()


class Clock:
    def __init__(self, t=100.0):
        self.t = t

    def __call__(self):
        return self.t


# ------------------------------------------------------------------------------ the device


@pytest.fixture
def device(tmp_path):
    clock = Clock()
    sim = SimulatedWatchdog(str(tmp_path / "watchdog"), 5.0, clock=clock).start()
    sim.fake_clock = clock
    yield sim
    sim.stop()


def test_open_arms_writes_kick_and_the_magic_close_disarms(device):
    dog = wd.Watchdog(device.path, 15).open()
    assert dog.armed
    assert dog.timeout is None  # a FIFO has no ioctls: the device keeps its own timeout
    dog.kick()
    dog.kick()
    assert wait_for(lambda: len(device.kicks) >= 2 and device.armed)
    dog.close(disarm=True)
    assert wait_for(lambda: device.disarms == 1 and not device.armed)
    device.fake_clock.t += 60
    assert not device.check()  # disarmed: no reset however long
    assert device.resets == []


def test_a_close_without_the_magic_character_leaves_it_armed_and_it_resets(device):
    dog = wd.Watchdog(device.path).open()
    dog.kick()
    assert wait_for(lambda: device.armed)
    dog.close(disarm=False)  # as when the platform manager dies
    assert wait_for(lambda: device.closes == 1)
    assert device.armed
    device.fake_clock.t += 5.5
    assert wait_for(lambda: device.resets == [device.fake_clock.t])


def test_a_device_that_cannot_be_opened_is_a_typed_error(tmp_path):
    with pytest.raises(wd.WatchdogError) as e:
        wd.Watchdog(str(tmp_path / "none")).open()
    assert "watchdog %s" % (tmp_path / "none") in str(e.value)
    os.mkfifo(tmp_path / "nobody-reads")  # a FIFO with no reader: ENXIO, never a hang
    with pytest.raises(wd.WatchdogError):
        wd.Watchdog(str(tmp_path / "nobody-reads")).open()


def test_ioctl_numbers_are_linux_watchdog_h():
    # _IOR('W', 5, int), _IOWR('W', 6, int), _IOR('W', 7, int) on every Linux architecture
    # that uses the generic ioctl layout: dir << 30 | size << 16 | type << 8 | nr
    def ioc(direction, nr):
        return direction << 30 | 4 << 16 | ord("W") << 8 | nr

    assert wd.WDIOC_KEEPALIVE == ioc(2, 5)
    assert wd.WDIOC_SETTIMEOUT == ioc(3, 6)
    assert wd.WDIOC_GETTIMEOUT == ioc(2, 7)


# ------------------------------------------------------------------------------ systemd


class FakeSystemd:
    """The notify socket systemd would bind: what came, one string per datagram."""

    def __init__(self, path):
        self.path = path
        self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
        self.sock.bind(path)
        self.sock.setblocking(False)

    def received(self):
        out = []
        try:
            while True:
                out.append(self.sock.recv(4096).decode())
        except BlockingIOError:
            return out


@pytest.fixture
def notify_socket(tmp_path):
    s = FakeSystemd(str(tmp_path / "notify"))
    yield s
    s.sock.close()


def received(systemd):
    return systemd.received()


def test_notify_sends_key_value_lines_in_one_datagram(notify_socket):
    n = Notifier.from_environ({"NOTIFY_SOCKET": notify_socket.path, "WATCHDOG_USEC": "4000000"})
    assert n.enabled and n.watchdog == 4.0
    assert n.ready("3 of 3 processes up")
    assert n.alive()
    assert received(notify_socket) == ["READY=1\nSTATUS=3 of 3 processes up", "WATCHDOG=1"]


def test_notify_to_an_abstract_socket():
    name = "obsw-test-%d" % os.getpid()
    s = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    s.bind("\0" + name)
    try:
        n = Notifier.from_environ({"NOTIFY_SOCKET": "@" + name})
        assert n.status("hello")
        assert s.recv(100) == b"STATUS=hello"
    finally:
        s.close()


def test_without_systemd_nothing_is_sent_and_a_watchdog_for_another_pid_is_ignored(tmp_path):
    assert not Notifier.from_environ({}).enabled
    assert not Notifier.from_environ({}).ready()
    other = Notifier.from_environ(
        {"NOTIFY_SOCKET": "/nowhere", "WATCHDOG_USEC": "1000", "WATCHDOG_PID": "1"}
    )
    assert other.watchdog is None
    gone = Notifier.from_environ({"NOTIFY_SOCKET": str(tmp_path / "gone")})
    assert not gone.ready() and gone.failed == 1  # systemd away: counted, not raised


# ------------------------------------------------------------------------------ the rule


class FakeChild:
    def __init__(self, name):
        self.name = name
        self.last_beat = None
        self.stopped = None
        self.restarts = 0


class FakeManager:
    def __init__(self, device=None, critical=None, names=("core", "can")):
        self.settings = {
            "deadline": 1.5,
            "heartbeat": 0.2,
            "watchdog": device,
            "watchdog_timeout": 5,
            "critical": critical,
        }
        self.children = [FakeChild(n) for n in names]
        self.lines = []

    def say(self, text):
        self.lines.append(text)


def test_the_watchdog_is_armed_when_all_are_up_and_kicked_only_while_all_are_healthy(device):
    clock = device.fake_clock
    m = FakeManager(device.path)
    s = Supervision(m, Notifier())
    core, can = m.children
    s.step(clock())
    assert s.state == wd.WAITING and not s.watchdog.armed  # nobody has beaten yet
    core.last_beat = can.last_beat = clock()
    s.step(clock())
    assert s.state == wd.FED and s.watchdog.kicks == 1
    clock.t += 0.1
    s.step(clock())
    assert s.watchdog.kicks == 1  # at most one kick per heartbeat period
    clock.t += 0.2
    core.last_beat = can.last_beat = clock()
    s.step(clock())
    assert s.watchdog.kicks == 2
    assert wait_for(lambda: len(device.kicks) == 2)  # the device took it at this time
    clock.t += 1.6  # can answers, core is silent past the deadline: hung
    can.last_beat = clock()
    s.step(clock())
    assert s.state == wd.STARVED and s.unhealthy(clock()) == ["core"]
    assert s.watchdog.kicks == 2
    seen = device.rounds
    assert wait_for(lambda: device.rounds >= seen + 2)  # it read whatever was written by now
    assert len(device.kicks) == 2 and device.resets == []
    clock.t += 3.5  # starved past the device's timeout: the board resets
    assert wait_for(lambda: len(device.resets) == 1)
    s.stop()


def test_a_restarted_process_feeds_it_again_and_a_stopped_one_no_longer_counts(device):
    clock = device.fake_clock
    m = FakeManager(device.path)
    s = Supervision(m, Notifier())
    core, can = m.children
    core.last_beat = can.last_beat = clock()
    s.step(clock())
    core.last_beat = None  # restarting
    clock.t += 0.5
    s.step(clock())
    assert s.state == wd.STARVED
    core.last_beat = can.last_beat = clock()  # back
    s.step(clock())
    assert s.state == wd.FED
    core.stopped = "refused its configuration"  # a mistake: a reset cannot fix it
    core.last_beat = None
    clock.t += 0.5
    can.last_beat = clock()
    s.step(clock())
    assert s.state == wd.FED
    s.stop()
    assert wait_for(lambda: device.disarms == 1)  # a planned stop disarms


def test_only_critical_processes_count(device):
    clock = device.fake_clock
    m = FakeManager(device.path, critical=["can"])
    s = Supervision(m, Notifier())
    m.children[1].last_beat = clock()
    s.step(clock())
    assert s.state == wd.FED  # core has never answered, but it is not critical
    s.stop()


def test_a_watchdog_that_fails_is_reported_and_the_obc_runs_on(tmp_path):
    m = FakeManager(str(tmp_path / "no-such-device"))
    s = Supervision(m, Notifier())
    for c in m.children:
        c.last_beat = 100.0
    s.step(100.0)
    assert s.state == wd.FAILED and "no-such-device" in s.error
    assert any("without its hardware watchdog" in line for line in m.lines)
    assert s.report()["watchdog"] == wd.FAILED


def test_systemd_hears_ready_status_and_watchdog(notify_socket):
    env = {"NOTIFY_SOCKET": notify_socket.path, "WATCHDOG_USEC": "2000000"}
    m = FakeManager()
    s = Supervision(m, Notifier.from_environ(env))
    core, can = m.children
    s.step(100.0)
    can.last_beat = core.last_beat = 100.5
    s.step(100.5)
    s.step(100.6)  # no new status, watchdog not due (every 1 s)
    s.step(101.6)
    core.last_beat = None
    s.step(101.7)
    s.stop()
    assert received(notify_socket) == [
        "STATUS=0 of 2 processes up; waiting for core, can",
        "WATCHDOG=1",
        "READY=1\nSTATUS=2 of 2 processes up",
        "WATCHDOG=1",
        "STATUS=1 of 2 processes up; waiting for core",
        "STOPPING=1",
    ]


# ------------------------------------------------------------------------------ health


def fake_tree(root, idle=800, busy=200, temp="48312\n"):
    (root / "proc").mkdir(parents=True, exist_ok=True)
    (root / "proc" / "stat").write_text(
        "cpu  %d 0 0 %d 0 0 0 0 0 0\ncpu0 1 2 3 4 5 6 7 8 0 0\n" % (busy, idle)
    )
    (root / "proc" / "meminfo").write_text(
        "MemTotal:        4000000 kB\nMemFree:          100000 kB\nMemAvailable:    3000000 kB\n"
    )
    (root / "proc" / "uptime").write_text("12345.67 40000.00\n")
    zone = root / "sys" / "class" / "thermal" / "thermal_zone0"
    zone.mkdir(parents=True, exist_ok=True)
    (zone / "temp").write_text(temp)


def test_health_figures_from_a_simulated_pi(tmp_path):
    fake_tree(tmp_path)
    h = HostHealth(str(tmp_path), str(tmp_path))
    first = h.sample()
    assert math.isnan(first["cpu_load"])  # a load needs two samples
    assert first["memory_used"] == 25.0
    assert first["temperature"] == 48.312
    assert first["uptime"] == 12345
    st = os.statvfs(str(tmp_path))
    assert first["disk_used"] == pytest.approx(100.0 * (st.f_blocks - st.f_bfree) / st.f_blocks)
    fake_tree(tmp_path, idle=800 + 300, busy=200 + 100)
    assert h.cpu_load() == 25.0  # 100 busy of 400 jiffies


def test_missing_or_garbled_files_give_nan_not_an_exception(tmp_path):
    h = HostHealth(str(tmp_path / "nothing"), str(tmp_path / "nothing"))
    got = h.sample()
    assert all(math.isnan(got[k]) for k in ("cpu_load", "memory_used", "disk_used", "temperature"))
    assert got["uptime"] == 0
    fake_tree(tmp_path, temp="hot\n")
    (tmp_path / "proc" / "stat").write_text("cpu x\n")
    assert math.isnan(HostHealth(str(tmp_path)).temperature())
    assert math.isnan(HostHealth(str(tmp_path)).cpu_load())


def test_the_obc_component_publishes_what_changed(tmp_path):
    fake_tree(tmp_path)

    class Node:
        def __init__(self):
            self.published = []

        def publish(self, comp, member, value):
            self.published.append((comp, member, value))

    class Provider:
        node = Node()

    class PinnedDisk(HostHealth):  # the disk is this machine's: other processes change it
        def disk_used(self):
            return 12.5

    health = ObcHealth(PinnedDisk(str(tmp_path), str(tmp_path)))
    health.il_bind(Provider)
    health.sample()
    names = [m for _, m, _ in Provider.node.published]
    assert names == ["memory_used", "disk_used", "temperature", "uptime"]  # cpu: NaN still
    assert health.temperature == 48.312
    Provider.node.published.clear()
    health.sample()
    health.status(2, wd.FED)
    health.status(2, wd.FED)
    assert Provider.node.published == [("Obc", "restarts", 2), ("Obc", "watchdog", wd.FED)]
    with pytest.raises(AttributeError):
        health.alive  # noqa: B018  (not a component that reports its own liveness)


# ------------------------------------------------------------------------------ the unit


def pi_mission(tmp_path):
    """The Raspberry Pi's mission folder, its key file (``/etc/obsw/tc.keys`` on the Pi) in
    ``tmp_path``: a mission that passes the check on this machine."""
    folder = tmp_path / "pi"
    shutil.copytree(os.path.join(ROOT, "boards", "raspberry-pi"), folder)
    keys = tmp_path / "tc.keys"
    r = subprocess.run([OBSW, "frames", "keygen", str(keys)], capture_output=True, text=True,
                       cwd=str(tmp_path))  # fmt: skip
    assert r.returncode == 0, r.stderr
    path = folder / "mission.json"
    doc = json.loads(path.read_text())
    doc["frames"]["keys"] = str(keys)
    doc.pop("$schema")
    path.write_text(json.dumps(doc))
    return str(path)


def test_install_service_dry_run_prints_the_unit_for_the_mission(tmp_path):
    mission = pi_mission(tmp_path)
    out = subprocess.run(
        [OBSW, "obc", "install-service", mission, "--dry-run", "--obsw", "/opt/obsw/bin/obsw"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    assert out == unit_text(mission=mission)  # the mission names /var/lib/obsw as its state
    assert "Type=notify" in out and "WatchdogSec=10" in out
    assert "ExecStart=/opt/obsw/bin/obsw obc serve %s --state /var/lib/obsw" % mission in out


def test_install_service_writes_under_root(tmp_path):
    mission = pi_mission(tmp_path)
    r = subprocess.run(
        [
            OBSW,
            "obc",
            "install-service",
            mission,
            "--root",
            str(tmp_path),
            "--state",
            "/srv/s",
            "--user",
            "pi",
            "--watchdog-sec",
            "20",
        ],  # fmt: skip
        capture_output=True,
        text=True,
    )
    assert r.returncode == 0, r.stderr
    path = tmp_path / "etc" / "systemd" / "system" / "obsw.service"
    assert r.stdout.splitlines()[0] == "wrote %s" % path
    text = path.read_text()
    assert "User=pi\n" in text and "WatchdogSec=20\n" in text and "--state /srv/s\n" in text
    assert oct(path.stat().st_mode & 0o777) == "0o644"


def test_install_service_refuses_bad_input(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text("{")
    mission = pi_mission(tmp_path)
    for args, said in (([str(bad)], str(bad) + ": $: not valid JSON"),
                       ([mission, "--state", "/a b"], "obsw obc: "),
                       ([mission, "--watchdog-sec", "0"], "obsw obc: ")):  # fmt: skip
        r = subprocess.run(
            [OBSW, "obc", "install-service", "--dry-run", *args], capture_output=True, text=True
        )
        assert r.returncode == 2, (args, r.stdout)
        assert r.stderr.startswith(said) and len(r.stderr.splitlines()) == 1, r.stderr


def test_config_and_install_service_check_the_mission_first(tmp_path):
    mission = pi_mission(tmp_path)
    doc = json.loads(open(mission).read())
    doc["pus"]["monitoring"] = [{"pmon": 1, "parameter": "Obc.temperature", "low": 0,
                                 "high": 80, "high_event": "monitoring.hot"}]  # fmt: skip
    open(mission, "w").write(json.dumps(doc))
    for action in (["config"], ["install-service", "--dry-run"]):
        r = subprocess.run([OBSW, "obc", *action, mission], capture_output=True, text=True)
        assert r.returncode == 2 and r.stdout == "", (action, r.stdout)
        lines = r.stderr.splitlines()
        assert len(lines) == 1 and lines[0].startswith(mission + ": $.pus.monitoring[0]")
        assert "monitoring.hot" in lines[0], lines


def test_the_shipped_unit_is_the_default_one():
    with open(os.path.join(ROOT, "boards", "raspberry-pi", "obsw.service")) as f:
        assert f.read() == unit_text()
    assert DEFAULTS["mission"] == "/etc/obsw/mission.json"


@pytest.mark.skipif(not shutil.which("systemd-analyze"), reason="systemd-analyze not installed")
def test_systemd_accepts_the_unit(tmp_path):
    path = tmp_path / "obsw.service"
    path.write_text(unit_text(obsw="/bin/true", user="root"))
    r = subprocess.run(["systemd-analyze", "verify", str(path)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


# ------------------------------------------------------------------------------ monitoring


class FakeStore:
    def __init__(self, saved=None):
        self.saved = dict(saved or {})

    def load(self, name, default=None):
        return self.saved.get(name, default)

    def save(self, name, value):
        self.saved[name] = value


def monitoring_app(store):
    db = load_sdb()
    app = ApplicationProcess(10, lambda raw: None, SimClock(0.0), store=store)
    app.register(OnBoardMonitoring(ParameterPool(db), db.events))
    return app, db


SAMPLE_CHECKS = [
    {"pmon": 43, "parameter": "Obc.temperature", "low": -40, "high": 80,
     "low_event": "monitoring.obc_low", "high_event": "monitoring.obc_high", "interval": 10,
     "repetitions": 3},
    {"pmon": 40, "parameter": "Obc.cpu_load", "low": 0, "high": 95, "enabled": False},
]  # fmt: skip


def test_the_missions_limit_checks_are_installed_at_the_first_start_only():
    store = FakeStore()
    app, db = monitoring_app(store)
    assert monitoring.install(app, db, SAMPLE_CHECKS) == 2
    s12 = app.services[12]
    t = s12.pmons[43]
    assert t.enabled and (t.d["low"], t.d["high"]) == (-40, 80)
    assert (t.d["interval"], t.d["repetitions"]) == (10, 3)
    assert t.d["high_event"] == db.event("monitoring.obc_high").id
    assert not s12.pmons[40].enabled
    assert [d["pmon"] for d, _ in store.saved["s12"]["pmons"]] == [43, 40]
    store.saved["s12"]["pmons"].pop()  # an operator deleted one: it stays deleted
    again, _ = monitoring_app(store)
    assert monitoring.install(again, db, SAMPLE_CHECKS) == 0
    assert list(again.services[12].pmons) == [43]


def test_the_missions_limits_are_engineering_values_installed_as_raw_ones():
    """Aurora's coil temperature is raw thermistor counts, calibrated by the spline
    (1365 counts, 0 degC) .. (1765 counts, 100 degC): 4 counts per degC."""
    from obsw.pus.sdb import load as load_db

    root = os.path.join(os.path.dirname(__file__), "..", "..")
    db = load_db(os.path.join(root, "examples", "aurora", "sdb.json"))
    app = ApplicationProcess(42, lambda raw: None, SimClock(0.0), store=FakeStore())
    app.register(OnBoardMonitoring(ParameterPool(db), db.events))
    entry = {"pmon": 1, "parameter": "Magnetorquer.coil_temp", "low": 15, "high": 35,
             "low_event": "monitoring.coil_cold", "high_event": "monitoring.coil_hot"}  # fmt: skip
    assert monitoring.install(app, db, [entry]) == 1
    d = app.services[12].pmons[1].d
    assert (d["low"], d["high"]) == (1365 + 4 * 15, 1365 + 4 * 35)
    assert d["high_event"] == db.event("monitoring.coil_hot").id
    entry = dict(entry, pmon=2, low=15.1, high=34.9)  # integer raw limits: inside, not beyond
    app.services[12].pmons.clear()
    app.store = None
    assert monitoring.install(app, db, [entry]) == 1
    d = app.services[12].pmons[2].d
    assert (d["low"], d["high"]) == (1365 + 61, 1365 + 139)


@pytest.mark.parametrize(
    "entry, why",
    [
        ({"pmon": 1, "parameter": "Obc.nothing", "low": 0, "high": 1}, "Obc.nothing"),
        ({"pmon": 1, "parameter": "Obc.cpu_load", "low": 5, "high": 1}, "low above high"),
        ({"pmon": 1, "parameter": "Obc.cpu_load", "high": 1}, "low"),
        ({"pmon": 1, "parameter": "Obc.cpu_load", "low": 0, "high": 1, "high_event": "x"}, "x"),
    ],
)
def test_a_bad_limit_check_is_a_configuration_error_naming_the_entry(entry, why):
    app, db = monitoring_app(FakeStore())
    with pytest.raises(ConfigError) as e:
        monitoring.install(app, db, [SAMPLE_CHECKS[0], entry])
    assert str(e.value).startswith("pus.monitoring[1]: ") and why in str(e.value)


def test_a_report_that_cannot_be_built_is_logged_and_raised_as_an_event():
    from obsw_host.obc.units import PusUnit

    app, db = monitoring_app(FakeStore())
    events, lines = [], []
    app.event_reporters.append(lambda *e: events.append(e) or True)
    unit = PusUnit.__new__(PusUnit)  # the unit's wiring without its sockets and processes
    unit.app, unit.sdb, unit.out, unit._reporting_unsent = app, db, lines.append, False
    app.unsent_listeners.append(unit._unsent)
    assert app.send_tm(3, 25, bytes(70000)) is None
    assert len(lines) == 1 and lines[0].startswith("TM[3,25] not sent: "), lines
    e = db.event("pus.report_failed")
    assert [x[0] for x in events] == [e.id]
    values = e.unpack(events[0][2])
    assert (values["service"], values["subtype"]) == (3, 25)
    assert "70" in values["reason"]


def test_a_datagram_the_socket_refuses_is_heard_with_its_reason():
    import asyncio

    from obsw_host.pus.onboard import _Udp

    loop = asyncio.new_event_loop()
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    sock.setblocking(False)
    counted, heard = [], []
    try:
        udp = _Udp(loop, sock, lambda *a: None, counted.append, lambda *a: heard.append(a))
        tm = bytes([0x08, 0x0A, 0xC0, 0, 0xFF, 0xFF, 0x20, 3, 25]) + bytes(70000)
        udp.sendto(tm, sock.getsockname())
    finally:
        loop.remove_reader(sock.fileno())
        loop.close()
        sock.close()
    assert counted == ["udp_errors"]
    assert len(heard) == 1 and heard[0][:2] == (3, 25)
    assert heard[0][2].startswith("UDP send of 70009 octets failed: "), heard
