"""The operator's commands for services 2, 3 and 14 (`obsw ground device|diag|functional|
forward`, `hk append`) against the sample OBC with its SpaceCAN process and simulated CPDU
nodes, run by the platform manager; every request's reports through the real command."""

import json
import os
import subprocess
import sys

import pytest
from obsw_host.mission import config as obc_config
from obsw_host.obc.platform import PlatformManager
from test_obc_assembly import free_port, sample, wait_for, write_config

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
ENV = dict(
    os.environ,
    PYTHONPATH=os.pathsep.join([os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]),
)
STATE_BITS = 0x000A0001  # CpduN (node 10), parameter 1: a register


@pytest.fixture(scope="module")
def obc(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("obc")
    doc = sample()
    doc["pus"]["port"] = port = free_port()
    doc["cfdp"]["port"] = free_port()
    doc["spacecan"]["channels"] = ["g-a-%d" % os.getpid(), "g-b-%d" % os.getpid()]
    config = obc_config.load(write_config(tmp, doc))
    pm = PlatformManager(config, out=lambda *a: None).start()
    try:
        assert wait_for(pm.up)
        yield port
    finally:
        pm.stop()


def ground(port, *args):
    cmd = [sys.executable, "-m", "obsw_host.cli", "ground", "--port", str(port), "--timeout", "8"]
    r = subprocess.run(
        cmd + ["--json"] + [str(a) for a in args],
        env=ENV,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert r.stdout, r.stderr
    return r.returncode, json.loads(r.stdout.splitlines()[-1])


def test_registers_on_off_and_cpdu_commands(obc):
    rc, out = ground(obc, "device", "load", "0x%08X=0x0005" % STATE_BITS)
    assert rc == 0, out
    rc, out = ground(obc, "device", "dump", "0x%08X" % STATE_BITS)
    assert rc == 0, out
    assert out["replies"][0]["registers"] == [[STATE_BITS, 5]]
    rc, out = ground(obc, "device", "on-off", "0x0A81", "0x0A00")  # CpduN line 1 on, 0 off
    assert rc == 0, out
    rc, out = ground(obc, "device", "cpdu", "0x0A02:100")
    assert rc == 0, out
    rc, out = ground(obc, "device", "on-off", "0x5581")  # no node 0x55
    assert rc == 1
    failure = out["failure"]  # start of execution, unknown ID, the address
    assert (failure["stage"], failure["code"], failure["data"]) == (2, 9, "5581")


def test_diagnostic_structures_and_functional_reporting(obc):
    rc, out = ground(obc, "diag", "create", 7, 1, "SolarPanel.angle")
    assert rc == 0, out
    rc, out = ground(obc, "diag", "report", 7)
    assert rc == 0, out
    assert out["replies"][0]["sid"] == 7
    rc, out = ground(obc, "hk", "append", 7, "SolarPanel.speed", "--diag")
    assert rc == 0, out
    rc, out = ground(obc, "diag", "structures", 7)
    assert out["replies"][0]["parameters"] == [1, 2]
    rc, out = ground(obc, "functional", "create", 3, "--diag", "7:on:5")
    assert rc == 0, out
    rc, out = ground(obc, "functional", "apply", 3)
    assert rc == 0, out
    rc, out = ground(obc, "diag", "properties", 7)
    assert out["replies"][0]["items"] == [{"sid": 7, "enabled": True, "interval": 5}]
    rc, out = ground(obc, "functional", "report")
    assert rc == 0, out
    rc, out = ground(obc, "forward", "diag", "add", "10:7")
    assert rc == 0, out
    rc, out = ground(obc, "forward", "diag", "report")
    assert rc == 0, out
    rc, out = ground(obc, "diag", "disable", 7)
    assert rc == 0, out
    rc, out = ground(obc, "diag", "delete", 7, 8)  # 8 unknown: nothing deleted
    assert rc == 1


def test_any_tc_with_its_application_data_in_hex(obc):
    rc, out = ground(obc, "tc", 3, 40, "0000")  # TC[3,40], N = 0: every definition
    assert rc == 0, out
    assert out["request"] == "TC[3,40]"
    assert "definitions" in out["replies"][0]
    rc, out = ground(obc, "tc", 3, 99)
    assert rc == 1
    assert out["failure"]["code"] == 4  # illegal subtype
