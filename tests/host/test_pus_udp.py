"""The on-board PUS process and the ground process on loopback UDP, with the sample panel."""

import argparse
import json

import pytest
from obsw.pus.messages import FAILURE_OUT_OF_RANGE
from obsw.pus.services.s20_parameters import RangeError
from obsw.store import Store
from obsw_host.commands import ground as ground_command
from obsw_host.mission.ports import app_port
from obsw_host.pus.ground import Ground, PusTimeout
from obsw_host.pus.onboard import Onboard
from obsw_host.sample import SDB_PATH, load_sdb
from obsw_host.solar_panel import SOLAR_PANEL, SolarPanel


@pytest.fixture
def system(tmp_path):
    sdb = load_sdb(SDB_PATH)
    panel = SolarPanel()
    onboard = Onboard(
        sdb,
        port=0,
        period=0.02,
        components=[(SOLAR_PANEL, panel)],
        store=Store(str(tmp_path / "ctx")),
    ).start()
    lines = []
    ground = Ground(sdb, target=onboard.address[:2], timeout=5.0, log=lines.append)
    yield onboard, ground, panel, lines
    ground.close()
    onboard.stop()


def test_port_convention(monkeypatch):
    sdb = load_sdb(SDB_PATH)
    monkeypatch.delenv("OBSW_PORT_BASE", raising=False)  # the default base
    assert app_port(sdb.apid("pus")) == 5000 + sdb.apid("pus")
    assert Onboard(sdb).port == 5000 + sdb.apid("pus")
    monkeypatch.setenv("OBSW_PORT_BASE", "23000")  # a base of this run's own
    assert app_port(sdb.apid("pus")) == 23000 + sdb.apid("pus")
    assert Onboard(sdb).port == 23000 + sdb.apid("pus")


def test_ping_and_its_reports(system):
    onboard, ground, panel, lines = system
    tx = ground.ping()
    assert tx.ok and tx.reply == {"alive": True}
    assert tx.verification() == ["acceptance success", "start success", "completion success"]
    assert lines[0].startswith("TC -> apid   10 seq     0  TC[17,1] are-you-alive")
    assert [line.split()[6] for line in lines[1:]] == ["TM[1,1]", "TM[1,3]", "TM[17,2]", "TM[1,7]"]


def test_housekeeping_and_parameters(system):
    onboard, ground, panel, lines = system
    tx = ground.housekeeping(1)
    assert tx.reply["values"] == {
        "SolarPanel.angle": 0.0,
        "SolarPanel.speed": 5.0,
        "SolarPanel.is_deployed": False,
    }
    assert ground.set_parameter("SolarPanel.speed", 7.5).ok
    assert panel.speed == 7.5
    tx = ground.get_parameters("SolarPanel.speed", "pus.tc_received")
    assert tx.reply["values"]["SolarPanel.speed"] == 7.5
    assert tx.reply["values"]["pus.tc_received"] == 3  # this request included
    with pytest.raises(RangeError):  # the database's range [0.1, 20]: refused on the ground
        ground.set_parameter("SolarPanel.speed", 50.0)
    data = ground.params.layout.pack({"items": [{"id": 2, "value": 50.0}]})
    tx = ground.wait(ground.send(ground.apid, 20, 3, data))  # and on board, if sent anyway
    assert (tx.failure["stage"], tx.failure["code"]) == (2, FAILURE_OUT_OF_RANGE)
    assert panel.speed == 7.5
    tx = ground.set_parameter("SolarPanel.angle", 1.0)  # read-only
    assert tx.failure["stage"] == 2


def test_structures_periodic_reports_and_context(system):
    onboard, ground, panel, lines = system
    assert ground.create_hk(9, 1, ["SolarPanel.angle", "pus.tm_sent"]).ok
    tx = ground.hk_structures([9])
    assert tx.reply["parameters"] == [1, 101]
    assert ground.enable_hk([9]).ok
    mark = len(ground.received)
    got = ground.wait_for(3, 25, timeout=5.0, since=mark)
    assert got is not None
    assert ground.set_hk_interval(9, 3).ok
    assert ground.hk_properties([9]).reply["items"] == [{"sid": 9, "enabled": True, "interval": 3}]
    assert ground.disable_hk([9]).ok
    assert ground.delete_hk([9]).ok
    saved = onboard.app.store.load("s03")  # both structure sets and functional reporting
    assert [s[0] for s in saved["hk"]] == [1, 2, 3, 4, 20]  # the sample's structures, 9 deleted
    assert saved["diag"] == saved["functional"] == []


def test_events_from_the_panel(system):
    onboard, ground, panel, lines = system
    ground.ping()
    mark = len(ground.received)

    def act():
        onboard.node.start("SolarPanel.deploy", timeout=1.0)
        onboard.node.poll()

    onboard.call(act)
    got = ground.wait_for(5, 2, timeout=5.0, since=mark)
    assert got[1] == {
        "id": 2,
        "severity": "low",
        "event": "SolarPanel.deployed",
        "data": {"hinges": 3},
    }
    assert ground.disable_events(["SolarPanel.angle_reached"]).ok
    assert ground.disabled_events().reply == {"ids": [1]}
    mark = len(ground.received)
    onboard.call(lambda: onboard.node.call("SolarPanel.set_angle", (10.0,), timeout=1.0))
    assert ground.ping().ok  # after the suppressed event would have come
    assert [tm for tm, _ in ground.received[mark:] if tm.service == 5] == []
    assert ground.enable_events(["SolarPanel.angle_reached"]).ok


def test_time_reports(system):
    onboard, ground, panel, lines = system
    mark = len(ground.received)
    assert ground.set_time_rate(0).ok
    got = ground.wait_for(9, 2, timeout=5.0, since=mark)
    assert got[1]["exponent"] == 0
    assert got[1]["time"] > 2.0e9  # TAI seconds since 1958, today


def test_timeout_names_the_transaction():
    sdb = load_sdb(SDB_PATH)
    with Ground(sdb, target=("127.0.0.1", 9), timeout=0.05) as ground:
        with pytest.raises(PusTimeout) as e:
            ground.ping()
    assert e.value.transaction.tc.service == 17


def _cli(system, capsys, *argv):
    onboard, _, _, _ = system
    parser = argparse.ArgumentParser()
    sub = parser.add_subparsers()
    ground_command.add_parser(sub)
    host, port = onboard.address[:2]
    args = parser.parse_args(["ground", "--host", host, "--port", str(port), *argv])
    status = args.func(args)
    return status, capsys.readouterr().out


def test_ground_commands(system, capsys):
    status, out = _cli(system, capsys, "ping")
    assert status == 0 and "completion success" in out
    status, out = _cli(system, capsys, "--json", "hk", "report", "1")
    result = json.loads(out)
    assert result["ok"] and result["replies"][0]["values"]["SolarPanel.speed"] == 5.0
    status, out = _cli(system, capsys, "params", "set", "SolarPanel.speed=6")
    assert status == 0
    status, out = _cli(system, capsys, "params", "get", "SolarPanel.speed")
    assert "SolarPanel.speed = 6 deg/s" in out
    status, out = _cli(system, capsys, "--json", "events", "disabled")
    assert json.loads(out)["replies"] == [{"ids": []}]
    status, out = _cli(system, capsys, "params", "set", "SolarPanel.angle=3")
    assert status == 1 and "start failure" in out
    status, out = _cli(system, capsys, "time", "rate", "0")
    assert status == 0


def test_demo():
    import pus_demo as demo

    lines = []
    assert demo.run(out=lines.append) == 0
    text = "\n".join(lines)
    for expected in (
        "TM[17,2] are-you-alive report",
        "TM[3,25] HK parameter report",
        "TM[20,2] parameter value report",
        "TM[1,4] start failure",
        "event=SolarPanel.angle_reached",
        "TM[9,2] CUC time report",
        "PUS demo done",
    ):
        assert expected in text
