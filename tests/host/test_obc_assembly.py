"""The OBC assembly: the mission configuration, one process with every PUS service, and the
platform manager restarting a killed and a hung process with service 5 events. Every wait
has a deadline; nothing asserts on time."""

import json
import os
import signal
import socket
import time

import pytest
from mission_ports import free_port
from obsw.pus import sdb as sdb_module
from obsw.pus.services.s02_device_access import DeviceUser
from obsw.pus.tm import PusTm
from obsw_host.mission import config as obc_config
from obsw_host.obc.platform import PlatformManager
from obsw_host.pus.ground import Ground
from obsw_host.sample import MISSION_DIR, MISSION_PATH

WAIT = 30.0


def wait_for(predicate, timeout=WAIT, step=0.02):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        v = predicate()
        if v:
            return v
        time.sleep(step)
    return predicate()


def sample():
    with open(MISSION_PATH) as f:
        return json.load(f)


def write_config(tmp_path, doc):
    """The sample's relative paths point into its folder: make them absolute here."""
    base = MISSION_DIR
    doc["sdb"] = os.path.join(base, doc["sdb"])
    if "obcp" in doc:
        doc["obcp"]["files"] = os.path.join(base, doc["obcp"]["files"])
    doc["state"] = str(tmp_path / "state")
    path = tmp_path / "mission.json"
    path.write_text(json.dumps(doc))
    return str(path)


def test_sample_loads_and_paths_are_relative_to_the_file():
    c = obc_config.load(MISSION_DIR)
    assert c.sdb_path == os.path.join(MISSION_DIR, "sdb.json")
    assert os.path.exists(c.sdb_path)
    assert c.host == "127.0.0.1"
    assert c.process_of("pus") == c.process_of("obcp") == c.process_of("cfdp")


@pytest.mark.parametrize(
    "change, key",
    [
        ({"processes": {}}, "processes"),
        ({"processes": {"a": ["pus", "warp_drive"]}}, "processes.a"),
        ({"processes": {"a": ["pus"], "b": ["pus"]}}, "processes.b"),
        ({"processes": {"a": ["pus"], "b": ["obcp"]}}, "processes"),
        ({"sdb": 5}, "sdb"),
        ({"platform": []}, "platform"),
    ],
)
def test_bad_configurations_name_the_key(tmp_path, change, key):
    doc = sample()
    doc.update(change)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(obc_config.ConfigError) as e:
        obc_config.load(str(path))
    assert e.value.key == key


def test_not_json_is_a_config_error(tmp_path):
    path = tmp_path / "bad.json"
    path.write_text("{not json")
    with pytest.raises(obc_config.ConfigError):
        obc_config.load(str(path))


class EventSink:
    """A UDP socket the PUS process sends every TM to (``pus.tm_to``); keeps event IDs."""

    def __init__(self):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.setblocking(False)
        self.address = "127.0.0.1:%d" % self.sock.getsockname()[1]
        self.events = []

    def poll(self):
        while True:
            try:
                raw = self.sock.recv(65536)
            except BlockingIOError:
                return self.events
            tm = PusTm.unpack(raw)
            if tm.service == 5:
                self.events.append((tm.data[0] << 8) | tm.data[1])


def test_platform_manager_restarts_killed_and_hung_processes(tmp_path):
    doc = sample()
    doc["processes"] = {"core": ["pus", "cfdp", "obcp", "SolarPanel"], "can": ["spacecan"]}
    doc["pus"]["port"] = pus_port = free_port()
    doc["cfdp"]["port"] = free_port()
    doc["spacecan"]["channels"] = ["t-a-%d" % os.getpid(), "t-b-%d" % os.getpid()]
    doc["platform"].update(heartbeat=0.2, deadline=1.5, max_failures=10)
    sink = EventSink()
    doc["pus"]["tm_to"] = sink.address
    config = obc_config.load(write_config(tmp_path, doc))
    db = sdb_module.load(config.sdb_path)
    ids = {n: db.event("platform." + n).id for n in ("started", "died", "restarted")}
    lines = []
    pm = PlatformManager(config, out=lines.append).start()
    try:
        assert wait_for(pm.up), lines
        ground = Ground(db, target=("127.0.0.1", pus_port), timeout=5.0)
        assert ground.ping().ok
        assert wait_for(lambda: sink.poll().count(ids["started"]) >= 2), sink.events
        # service 2 reaches the CPDU node through the SpaceCAN process: a SpaceCAN
        # connection test (17,1) answered by the node's (17,2) in TM[2,12]
        dev = ground.proc.register(DeviceUser())
        tx = ground.wait(dev.logical_acquire(db.apid("pus"), [(10, 17, 1, b"")]))
        assert tx.ok, tx.verification()
        items = tx.reply["items"]
        assert [i[:3] for i in items] == [(10, 17, 2)]

        can = pm.child("can")
        old = can.pid
        os.kill(old, signal.SIGKILL)
        assert wait_for(lambda: can.restarts == 1 and can.last_beat is not None), lines
        assert can.pid != old
        assert wait_for(lambda: ids["died"] in sink.poll() and ids["restarted"] in sink.events)

        core = pm.child("core")
        os.kill(core.pid, signal.SIGSTOP)  # hung: alive, silent
        assert wait_for(lambda: core.restarts == 1 and core.last_beat is not None), lines
        assert any("silent" in text for _, text in pm.log)
        assert ground.ping().ok  # the restarted PUS process serves again
        assert wait_for(lambda: sink.poll().count(ids["restarted"]) >= 2), sink.events
        ground.close()
    finally:
        pm.stop()
        sink.sock.close()
    assert all(c.popen.poll() is not None for c in pm.children)
