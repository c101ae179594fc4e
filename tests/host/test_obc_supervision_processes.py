"""The supervision chain with real OBC processes: the watchdog fed while every process is
healthy, starved while a hung (SIGSTOP) process is restarted, fed again after; systemd told;
the OBC's health in its parameters; and the operators' settings (service 20 values,
monitoring, event-actions, the time-based schedule) through a restart of the PUS process, of a
component, and of the whole OBC. Every wait has a deadline; nothing asserts on time."""

import os
import signal

from obsw.il.node import Node
from obsw_host.il.transport import SocketTransport
from obsw_host.mission import config as obc_config
from obsw_host.obc import watchdog as wd
from obsw_host.obc.platform import PlatformManager
from obsw_host.obc.sdnotify import Notifier
from obsw_host.pus.ground import Ground
from obsw_sim.watchdog import SimulatedWatchdog
from test_obc_assembly import free_port, sample, wait_for, write_config
from test_obc_supervision import FakeSystemd, fake_tree


def mission(tmp_path, **platform):
    doc = sample()
    doc["processes"] = {"core": ["pus"], "panel": ["SolarPanel"]}
    doc["pus"]["port"] = free_port()
    doc["cfdp"]["port"] = free_port()
    doc["platform"].update(heartbeat=0.2, deadline=1.5, max_failures=10, **platform)
    return obc_config.load(write_config(tmp_path, doc))


def ground_of(config, pm):
    port = config.section("pus")["port"]
    return Ground(pm.topology.sdb, target=("127.0.0.1", port), timeout=5.0)


def value(ground, key):
    tx = ground.get_parameters(key)
    return tx.reply["values"][key] if tx.ok else None


def near(got, expected):
    return got is not None and abs(got - expected) < 1e-3  # float32 on the wire


def test_watchdog_and_systemd_follow_the_health_of_every_process(tmp_path):
    tree = tmp_path / "pi"
    fake_tree(tree)
    device = SimulatedWatchdog(str(tmp_path / "watchdog"), 30.0).start()
    systemd = FakeSystemd(str(tmp_path / "notify"))
    config = mission(tmp_path, watchdog=device.path, health_root=str(tree), health_period=0.2)
    lines = []
    notifier = Notifier(systemd.path, 1_000_000)
    pm = PlatformManager(config, out=lines.append, notifier=notifier).start()
    sv = pm.supervision
    ground = None
    try:
        assert wait_for(pm.up), lines
        assert wait_for(lambda: sv.state == wd.FED and len(device.kicks) >= 2), lines
        assert wait_for(lambda: any(m.startswith("READY=1") for m in systemd.received()))
        ground = ground_of(config, pm)
        assert wait_for(lambda: near(value(ground, "Obc.temperature"), 48.312)), lines
        assert wait_for(lambda: value(ground, "Obc.watchdog") == wd.FED)

        panel = pm.child("panel")
        os.kill(panel.pid, signal.SIGSTOP)  # hung: alive, silent
        assert wait_for(lambda: sv.state == wd.STARVED), lines
        starved_at = len(device.kicks)
        assert wait_for(lambda: panel.restarts == 1 and panel.last_beat is not None), lines
        assert wait_for(lambda: sv.state == wd.FED), lines
        assert any("panel" in t and "silent" in t for _, t in pm.log)
        assert wait_for(lambda: len(device.kicks) > starved_at)
        assert device.resets == []  # recovered well within the watchdog's timeout
        assert wait_for(lambda: value(ground, "Obc.restarts") == 1)
        said = systemd.received()
        assert "WATCHDOG=1" in said
        assert "STATUS=1 of 2 processes up; waiting for panel" in said
    finally:
        if ground is not None:
            ground.close()
        pm.stop()
        assert wait_for(lambda: device.disarms == 1)  # a planned stop: magic close
        device.stop()
    assert "STOPPING=1" in systemd.received()
    systemd.sock.close()


def settings(ground):
    """The settings an operator made, as the OBC reports them now."""
    monitors = ground.monitors()
    actions = ground.actions()
    scheduled = ground.scheduled()
    return {
        "speed": value(ground, "SolarPanel.speed"),
        "distance": value(ground, "nav.distance"),
        "monitors": sorted(d["pmon"] for d in monitors.reply["items"]) if monitors.ok else None,
        "actions": len(actions.reply["items"]) if actions.ok else None,
        "scheduled": len(scheduled.reply["activities"]) if scheduled.ok else None,
    }


def test_settings_survive_restarts_of_pus_of_a_component_and_of_the_obc(tmp_path):
    config = mission(tmp_path)
    lines = []
    pm = PlatformManager(config, out=lines.append).start()
    ground = None
    try:
        assert wait_for(pm.up), lines
        ground = ground_of(config, pm)
        assert wait_for(lambda: value(ground, "SolarPanel.speed") == 5.0), lines
        assert ground.set_parameters({"SolarPanel.speed": 8.0, "nav.distance": 1234}).ok
        assert ground.add_limit_monitor(
            1, "SolarPanel.speed", 0.5, 10.0, "monitoring.speed_low", "monitoring.speed_high"
        ).ok
        action = ground.parameter_request({"SolarPanel.speed": 5.0})
        assert ground.add_action("monitoring.speed_high", action).ok
        timed = ground.function_request("SolarPanel.set_angle", angle=15.0)
        assert ground.schedule_in(3600.0, timed).ok
        checks = [1, 40, 41, 42, 43]  # the operator's and the mission's limit checks
        made = {"speed": 8.0, "distance": 1234, "monitors": checks, "actions": 1, "scheduled": 1}
        assert settings(ground) == made

        core = pm.child("core")
        os.kill(core.pid, signal.SIGKILL)  # the PUS process
        assert wait_for(lambda: core.restarts == 1 and core.last_beat is not None), lines
        assert wait_for(lambda: settings(ground) == made), settings(ground)

        panel = pm.child("panel")
        os.kill(panel.pid, signal.SIGKILL)  # the component starts from its defaults ...
        assert wait_for(lambda: panel.restarts == 1 and panel.last_beat is not None), lines
        assert wait_for(lambda: settings(ground) == made), settings(ground)  # ... set again
    finally:
        if ground is not None:
            ground.close()
        pm.stop()

    pm = PlatformManager(config, out=lines.append).start()  # `obsw obc serve` again
    ground = None
    try:
        assert wait_for(pm.up), lines
        ground = ground_of(config, pm)
        assert wait_for(lambda: settings(ground) == made), settings(ground)
    finally:
        if ground is not None:
            ground.close()
        pm.stop()


WORKER = '''
import threading
import time

from obsw.il.interface import Interface, Operation

Worker = Interface("Worker", 0x500, [Operation("freeze", 1, ())])


class Work:
    """A component whose work runs in a thread; freeze() blocks that thread for good."""

    def __init__(self):
        self.last = time.monotonic()
        self.frozen = threading.Event()
        threading.Thread(target=self._run, daemon=True).start()

    def _run(self):
        while True:
            if self.frozen.is_set():
                threading.Event().wait()  # a deadlock: the process lives, the work is stuck
            self.last = time.monotonic()
            time.sleep(0.05)

    def freeze(self):
        self.frozen.set()

    def alive(self):
        return time.monotonic() - self.last < 1.0
'''


def test_a_hung_unit_inside_a_live_process_is_restarted(tmp_path):
    (tmp_path / "worker.py").write_text(WORKER)
    doc = sample()
    doc["processes"] = {"core": ["pus"], "work": ["Worker"]}
    doc["components"]["Worker"] = {"module": "worker.py", "class": "Work"}
    doc["pus"]["port"] = free_port()
    doc["cfdp"]["port"] = free_port()
    doc["platform"].update(heartbeat=0.2, deadline=1.5, max_failures=10)
    path = write_config(tmp_path, doc)
    config = obc_config.load(path)
    lines = []
    pm = PlatformManager(config, out=lines.append).start()
    node = Node("test-user")
    transport = SocketTransport(node, config.il_directory, listen=False)
    try:
        assert wait_for(pm.up), lines
        work = pm.child("work")
        old = work.pid
        node.call("Worker.freeze", timeout=5.0)
        assert wait_for(lambda: work.restarts == 1 and work.last_beat is not None), lines
        assert work.pid != old  # the stuck process was killed and a new one answers
        assert any("work" in t and "silent" in t for _, t in pm.log)
    finally:
        transport.close()
        pm.stop()
