"""The interaction layer across real processes: proxies, publications, a provider killed and
restarted, cycle detection over sockets. Readiness is polled with deadlines, never slept."""

import os
import signal
import subprocess
import sys
import time

import pytest
from obsw.il.errors import (
    ComponentError,
    CycleError,
    ProviderError,
    UnavailableError,
)
from obsw.il.node import Node
from obsw_host.il.directory import Directory
from obsw_host.il.processes import python_path, spawn, stop
from obsw_host.il.transport import SocketTransport
from obsw_host.solar_panel import SOLAR_PANEL

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from il_peer import interface as peer_interface  # noqa: E402

pytestmark = pytest.mark.skipif(not hasattr(os, "fork"), reason="needs Unix processes")


def spawn_peer(directory, name):
    env = dict(os.environ, PYTHONPATH=python_path() + os.pathsep + HERE)
    return subprocess.Popen(
        [sys.executable, "-m", "il_peer", "--dir", directory, name],
        env=env,
        stdin=subprocess.DEVNULL,
    )


def wait_for(predicate, timeout=20.0):
    """Poll ``predicate`` until true or the deadline (a readiness check, not a timing one)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.01)
    raise AssertionError("condition not met within %ss" % timeout)


@pytest.fixture
def directory(tmp_path):
    return str(tmp_path)


@pytest.fixture
def procs():
    started = []
    yield started
    for p in started:
        stop(p)


@pytest.fixture
def user(directory):
    node = Node("test-user")
    transport = SocketTransport(node, directory, listen=False)
    yield node
    transport.close()


def test_proxy_calls_across_processes(directory, procs, user):
    procs.append(spawn("obsw_host.solar_panel", directory))
    panel = user.proxy(SOLAR_PANEL, timeout=20.0)
    assert panel.get("angle") == 0.0
    with pytest.raises(ComponentError) as e:
        panel.set_angle(10)
    assert e.value.code == "NOT_DEPLOYED"
    updates = []
    pending = panel.deploy(on_status=lambda p, state, value: updates.append(value))
    assert pending.result(timeout=20.0) == "deployed"
    assert updates[1:] == [
        {"hinge": 1, "of": 3},
        {"hinge": 2, "of": 3},
        {"hinge": 3, "of": 3},
        "deployed",
    ]
    assert panel.set_angle(30) == 30.0
    assert panel.angle == 30.0
    panel.set("speed", 7)
    assert user.get("SolarPanel.speed", timeout=5.0) == 7.0
    with pytest.raises(ProviderError) as e:
        panel.set("speed", 100)
    assert e.value.type == "ValueError"
    assert e.value.data == ["speed must be in (0, 20] deg/s", 100]
    with pytest.raises(ComponentError) as e:
        panel.set_angle(-120)
    assert e.value.data == {"angle": -120, "limit": 90.0}


def test_bytes_int_keys_and_nesting_survive(directory, procs, user):
    procs.append(spawn_peer(directory, "A"))
    a = user.proxy(peer_interface("A", 65), timeout=20.0)
    sub = a.subscribe("tick", length=4)
    assert a.emit(1, 3) == 1
    pub = sub.receive(timeout=10.0)
    assert pub.value == {"i": 0, "blob": b"\x00\x00\x00"}
    assert a.add(2**70, 1).result(timeout=10.0) == 2**70 + 1
    assert a.add([b"x"], [{2: None}]).result(timeout=10.0) == [b"x", {2: None}]


def test_large_payloads_cross_in_pieces(directory, procs, user):
    # events and arguments far larger than one socket read arrive whole
    procs.append(spawn_peer(directory, "A"))
    a = user.proxy(peer_interface("A", 65), timeout=20.0)
    sub = a.subscribe("tick", length=4)
    assert a.emit(2, 1 << 20) == 2
    for i in range(2):
        assert sub.receive(timeout=10.0).value == {"i": i, "blob": bytes(1 << 20)}
    big = bytes(range(256)) * 2048
    assert a.add(big, b"!").result(timeout=10.0) == big + b"!"


def test_user_recovers_after_provider_restart(directory, procs, user):
    procs.append(spawn("obsw_host.solar_panel", directory))
    panel = user.proxy(SOLAR_PANEL, timeout=20.0)
    panel.deploy().result(timeout=20.0)
    events = panel.subscribe("angle_reached", length=8)
    assert panel.set_angle(12) == 12.0
    assert events.receive(timeout=10.0).value == {"angle": 12.0}
    first = Directory(directory).read("SolarPanel")

    procs[0].send_signal(signal.SIGKILL)
    procs[0].wait(10)
    # the provider is gone: a short call fails, bounded by its timeout and retries
    short = user.proxy(SOLAR_PANEL, timeout=0.2, retries=1)
    before = user.retries
    with pytest.raises(UnavailableError):
        short.get("angle")
    assert user.retries == before + 1

    procs.append(spawn("obsw_host.solar_panel", directory))
    assert panel.get("angle") == 0.0  # found again: a fresh process, a fresh panel
    second = Directory(directory).read("SolarPanel")
    assert second["pid"] == procs[1].pid != first["pid"]
    assert second["address"] != first["address"]
    panel.deploy().result(timeout=20.0)
    assert panel.set_angle(-7) == -7.0
    # the subscription made before the crash was renewed with the new process
    assert events.receive(timeout=10.0).value == {"angle": -7.0}


def test_subscription_renewed_without_calls(directory, procs, user):
    procs.append(spawn_peer(directory, "A"))
    a = user.proxy(peer_interface("A", 65), timeout=20.0)
    ticks = a.subscribe("tick", length=64)
    old_pid = a.pid()
    procs[0].send_signal(signal.SIGKILL)
    procs[0].wait(10)
    procs.append(spawn_peer(directory, "A"))
    wait_for(lambda: Directory(directory).lookup("A"))
    # another user makes the new process publish; ours only listens
    other = Node("other-user")
    with SocketTransport(other, directory, listen=False):
        other_a = other.proxy(peer_interface("A", 65), timeout=20.0)
        assert other_a.pid() != old_pid

        def got_tick():
            other_a.emit(1, 0)
            return ticks.receive(timeout=0.2)

        assert wait_for(got_tick).value == {"i": 0, "blob": b""}


def test_fan_out_across_processes(directory, procs, user):
    procs.append(spawn_peer(directory, "B"))
    b = user.proxy(peer_interface("B", 66), timeout=20.0)
    subs = [b.subscribe("tick", length=128) for _ in range(5)]
    assert b.emit(100, 16) == 100
    for sub in subs:
        got = [sub.receive(timeout=10.0).value["i"] for _ in range(100)]
        assert got == list(range(100))
        assert sub.dropped == 0


def test_cycle_across_processes_fails_at_once(directory, procs, user):
    procs.append(spawn_peer(directory, "A"))
    procs.append(spawn_peer(directory, "B"))
    a = user.proxy(peer_interface("A", 65), timeout=20.0)
    b = user.proxy(peer_interface("B", 66), timeout=20.0)
    assert b.ping([]) == "B"
    assert a.ping(["B"]) == "A>B"
    # a deadlock would end in CallTimeoutError after the peers' 5 s; a CycleError is at once
    with pytest.raises(CycleError) as e:
        a.ping(["B", "A"])
    assert e.value.cycle == ("A", "B", "A")
    assert "A -> B -> A" in str(e.value)
    with pytest.raises(CycleError) as e:
        user.call("B.ping", (["A", "B"],), timeout=20.0)
    assert e.value.cycle == ("B", "A", "B")


def test_provider_stops_cleanly_and_withdraws(directory, procs, user):
    proc = spawn("obsw_host.solar_panel", directory)
    procs.append(proc)
    assert user.get("SolarPanel.angle", timeout=20.0) == 0.0
    assert stop(proc) == 0
    assert Directory(directory).read("SolarPanel") is None
    with pytest.raises(UnavailableError):
        user.get("SolarPanel.angle", timeout=0.3)
