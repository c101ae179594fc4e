"""Bounds where input arrives (issue 34): the TM subscribers of an on-board process, and the
mission's files (size, nesting, symbolic links out of the folder, devices), each through
`obsw mission check` and `obsw obc serve` as an operator meets them; the numbers are in
docs/hardening.md. Every wait has a deadline; nothing asserts on time."""

import os
import shutil
import socket

from obsw_host import sample
from obsw_host.mission.folder import MAX_JSON_FILE, MAX_PROCEDURE
from obsw_host.mission.new import free_fleet_base
from obsw_host.pus.tm_fanout import MAX_SUBSCRIBERS, SUBSCRIBE, TmFanout
from obsw_sim.brick import LiveObc, make_mission
from test_mission_examples import ENV, obsw


class Clock:
    def __init__(self):
        self.t = 0.0

    def __call__(self):
        return self.t


def test_tm_subscribers_are_bounded():
    clock = Clock()
    fan = TmFanout([("127.0.0.1", 1)], linger=60.0, clock=clock)
    for port in range(MAX_SUBSCRIBERS):
        assert not fan.heard(SUBSCRIBE, ("127.0.0.1", 1000 + port))
    assert len(fan.subscribers) == MAX_SUBSCRIBERS and fan.refused == 0
    assert not fan.heard(SUBSCRIBE, ("127.0.0.1", 5000))  # one above: refused
    assert ("127.0.0.1", 5000) not in fan.subscribers and fan.refused == 1
    clock.t = 1.0
    assert fan.heard(b"\x18" * 10, ("127.0.0.1", 5001))  # a TC: handled, and answered
    assert ("127.0.0.1", 5001) in fan.subscribers and ("127.0.0.1", 1000) not in fan.subscribers
    assert len(fan.subscribers) == MAX_SUBSCRIBERS and fan.refused == 2
    clock.t = 30.0
    fan.heard(SUBSCRIBE, ("127.0.0.1", 1001))  # a known one is kept fresh
    assert fan.refused == 2
    clock.t = 60.0  # at the linger: the others are still there
    assert not fan.heard(SUBSCRIBE, ("127.0.0.1", 5002)) and fan.refused == 3
    clock.t = 61.5  # past it: the silent ones make room, the fresh ones stay
    fan.heard(SUBSCRIBE, ("127.0.0.1", 5003))
    assert set(fan.subscribers) == {("127.0.0.1", 1001), ("127.0.0.1", 5003)}
    assert len(fan.targets()) == 3


def test_a_flood_of_subscriptions_does_not_stall_the_obc(tmp_path):
    obc = LiveObc(make_mission(str(tmp_path / "sat"), ("pus",)), str(tmp_path / "state"))
    obc.start()
    try:
        from obsw_host.mission.ids import MissionIds

        port = MissionIds.locate(obc.mission).ports.pus - 5000 + obc.base
        for _ in range(4):  # four bursts, from as many ports as datagrams
            for _ in range(2500):
                s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
                s.sendto(SUBSCRIBE, ("127.0.0.1", port))
                s.close()
            assert obc.ping(), obc.text()
        assert not obc.said("restarting"), obc.text()
    finally:
        obc.stop()


def mission_copy(tmp_path):
    folder = tmp_path / "m"
    shutil.copytree(os.path.dirname(sample.MISSION_PATH), folder)
    return folder


def check(folder):
    return obsw("mission", "check", str(folder))


def test_deep_json_in_a_mission_file_is_a_problem_not_a_traceback(tmp_path):
    folder = mission_copy(tmp_path)
    deep = '{"x": ' + "[" * 10000 + "]" * 10000 + "}"
    env = dict(ENV, OBSW_PORT_BASE=str(free_fleet_base(1)))
    for name in ("mission.json", "sdb.json"):
        good = (folder / name).read_text()
        (folder / name).write_text(deep)
        r = check(folder)
        assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
        assert "nest" in (r.stdout + r.stderr).lower(), r.stdout + r.stderr
        r = obsw("obc", "serve", str(folder), "--state", str(tmp_path / "s"), env=env)
        assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
        (folder / name).write_text(good)


def test_a_procedure_linked_to_a_device_or_out_of_the_folder_is_refused(tmp_path):
    folder = mission_copy(tmp_path)
    procs = folder / "procedures"
    os.symlink("/dev/zero", str(procs / "zero.plt"))
    r = check(folder)
    assert r.returncode == 2 and "zero.plt" in r.stdout + r.stderr, r.stdout + r.stderr
    assert "symbolic link out of the mission folder" in r.stdout + r.stderr
    os.remove(str(procs / "zero.plt"))
    outside = tmp_path / "outside.plt"
    outside.write_text("procedure main\nend procedure\n")
    os.symlink(str(outside), str(procs / "out.plt"))
    r = check(folder)
    assert r.returncode == 2 and "out.plt" in r.stdout + r.stderr
    os.remove(str(procs / "out.plt"))
    big = procs / "big.plt"
    big.write_text("-- padding\n" * (MAX_PROCEDURE // 11 + 1))
    r = check(folder)
    assert r.returncode == 2 and "more than the %d" % MAX_PROCEDURE in r.stdout + r.stderr


def test_a_huge_database_is_refused_before_it_is_read(tmp_path):
    folder = mission_copy(tmp_path)
    with open(folder / "sdb.json", "ab") as f:
        f.truncate(MAX_JSON_FILE + 1)  # sparse: nothing to write
    r = check(folder)
    assert r.returncode == 2, r.stdout + r.stderr
    assert "more than the %d" % MAX_JSON_FILE in r.stdout + r.stderr
    with open(folder / "sdb.json", "r+b") as f:
        f.truncate(MAX_JSON_FILE)  # at the limit: read, then judged as JSON
    r = check(folder)
    assert "more than the" not in r.stdout + r.stderr
