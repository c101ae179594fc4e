"""Plug-in components under the platform manager: in a process of their own, started and
restarted like built-in units, and followed by the PUS parameter pool whether they start
after the OBC or restart (their values in PUS are never frozen). Every wait has a deadline."""

import json
import os
import signal

from obsw.il.node import Node
from obsw_host.il.processes import spawn, stop
from obsw_host.il.transport import SocketTransport
from obsw_host.mission import config as obc_config
from obsw_host.obc.platform import PlatformManager
from obsw_host.pus.ground import Ground
from obsw_host.sample import MISSION_PATH
from test_obc_assembly import free_port, sample, wait_for, write_config


def mission(tmp_path, processes):
    doc = sample()
    doc["processes"] = processes
    doc["pus"]["port"] = free_port()
    doc["cfdp"]["port"] = free_port()
    doc["platform"].update(heartbeat=0.2, deadline=1.5)
    return obc_config.load(write_config(tmp_path, doc))


def speed(ground):
    tx = ground.get_parameters("SolarPanel.speed")
    return tx.reply["values"]["SolarPanel.speed"] if tx.ok else None


def set_speed(config, value):
    """Set the panel's speed on the component itself (not through PUS)."""
    node = Node("test-user")
    transport = SocketTransport(node, config.il_directory, listen=False)
    try:
        node.set("SolarPanel.speed", value, timeout=5.0)
    finally:
        transport.close()


def test_a_component_in_its_own_process_is_supervised_and_followed(tmp_path):
    config = mission(tmp_path, {"core": ["pus"], "panel": ["SolarPanel"]})
    lines = []
    pm = PlatformManager(config, out=lines.append).start()
    ground = None
    try:
        assert wait_for(pm.up), lines
        db = pm.topology.sdb
        ground = Ground(db, target=("127.0.0.1", config.section("pus")["port"]), timeout=5.0)
        assert wait_for(lambda: speed(ground) == 5.0), lines  # the panel's own value
        set_speed(config, 7.5)
        assert wait_for(lambda: speed(ground) == 7.5)  # published, cached
        panel = pm.child("panel")
        old = panel.pid
        os.kill(old, signal.SIGKILL)
        assert wait_for(lambda: panel.restarts == 1 and panel.last_beat is not None), lines
        assert panel.pid != old
        # the restarted panel starts from its own state again: PUS reads it anew
        assert wait_for(lambda: speed(ground) == 5.0), lines
        set_speed(config, 3.0)  # and its publications reach PUS again
        assert wait_for(lambda: speed(ground) == 3.0)
    finally:
        if ground is not None:
            ground.close()
        pm.stop()
    assert pm.power_cycles == 0


def test_a_component_that_starts_after_the_obc(tmp_path):
    config = mission(tmp_path, {"core": ["pus"]})
    lines = []
    pm = PlatformManager(config, out=lines.append).start()
    ground = None
    panel = None
    try:
        assert wait_for(pm.up), lines
        ground = Ground(pm.topology.sdb, target=("127.0.0.1", config.section("pus")["port"]),
                        timeout=5.0)  # fmt: skip
        assert speed(ground) == 0.0  # nobody provides it: the type's zero
        panel = spawn("obsw_host.solar_panel", config.il_directory)
        assert wait_for(lambda: speed(ground) == 5.0), lines
        set_speed(config, 9.0)
        assert wait_for(lambda: speed(ground) == 9.0)
    finally:
        if panel is not None:
            stop(panel)
        if ground is not None:
            ground.close()
        pm.stop()


def test_the_sample_mission_names_its_solar_panel_as_a_plug_in():
    with open(MISSION_PATH) as f:
        doc = json.load(f)
    assert doc["components"] == {"SolarPanel": {"module": "obsw_host.solar_panel"}}
    assert "SolarPanel" in doc["processes"]["obc"]
