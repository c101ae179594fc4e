"""Interop with LibreCube's spacecan 0.8.1 (test oracle) on python-can virtual channels, both ways.

Our controller drives spacecan's responder, and spacecan's controller drives our responder, at
frame level (the bytes match the captured trace) and at service level (17, 20, 3, 8, time frames,
bus switch). spacecan has no virtual transport: its socketcan module gets a python-can virtual
bus instead, and its timers are made daemon threads so a leftover timer cannot hang the run.
Every wait is bounded by a deadline.
"""

import json
import threading
import time
import types
import uuid

import can as can
import pytest
import spacecan as spacecan
from obsw.spacecan import events as ev  # noqa: E402
from obsw.spacecan.controller import COMPLETED, REJECTED, TIMEOUT, Controller  # noqa: E402
from obsw.spacecan.nodedef import NodeDefinition  # noqa: E402
from obsw.spacecan.responder import Responder  # noqa: E402
from obsw_host.spacecan.adapter import BusFaults, CanAdapter  # noqa: E402

HB = 0.1  # heartbeat period for both sides: failover in (3 + 1) * 0.1 s
NODE = {
    "parameters": [
        {"parameter_id": 1, "parameter_name": "mode", "encoding": "u8", "value": 3},
        {"parameter_id": 2, "parameter_name": "volt", "encoding": "f32", "value": 7.5},
        {"parameter_id": 3, "parameter_name": "count", "encoding": "u32", "value": 0x12345678},
        {"parameter_id": 4, "parameter_name": "temp", "encoding": "i16", "value": -20},
    ],
    "housekeeping_reports": [
        {"report_id": 1, "interval": 1, "enabled": False, "parameter_ids": [1, 4]},
        {"report_id": 2, "interval": 0.2, "enabled": False, "parameter_ids": [2]},
    ],
    "functions": [
        {
            "function_id": 1,
            "function_name": "set_line",
            "arguments": [{"argument_id": 1, "argument_name": "line", "encoding": "u8"}],
        },
        {"function_id": 2, "function_name": "reset"},
    ],
}


def wait_until(pred, timeout=3.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if pred():
            return True
        time.sleep(0.005)
    return bool(pred())


class _DaemonTimer(threading.Timer):
    def __init__(self, *a, **kw):
        super().__init__(*a, **kw)
        self.daemon = True


@pytest.fixture
def peer_env(monkeypatch, tmp_path):
    import spacecan.primitives.timer as sc_timer
    import spacecan.transport.socketcan as sc_socket

    shim = types.SimpleNamespace(
        Bus=lambda interface, channel: can.Bus(interface="virtual", channel=channel),
        Message=can.Message,
        exceptions=can.exceptions,
    )
    monkeypatch.setattr(sc_socket, "can", shim)
    monkeypatch.setattr(sc_timer, "threading", types.SimpleNamespace(Timer=_DaemonTimer))
    tag = uuid.uuid4().hex[:8]
    path = tmp_path / "node.json"
    path.write_text(json.dumps(NODE))
    env = types.SimpleNamespace(channels=("scA" + tag, "scB" + tag), nodefile=str(path), stops=[])
    env.sniff = can.Bus(interface="virtual", channel=env.channels[0])
    env.sniff_b = can.Bus(interface="virtual", channel=env.channels[1])
    yield env
    for stop in reversed(env.stops):
        try:
            stop()
        except Exception:
            pass
    env.sniff.shutdown()
    env.sniff_b.shutdown()
    for t in threading.enumerate():  # spacecan's timers: cancel any left over
        if isinstance(t, threading.Timer):
            t.cancel()


def sniffed(bus, hb=False):
    out = []
    while True:
        m = bus.recv(0)
        if m is None:
            return out
        if hb or m.arbitration_id != 0x700:
            out.append((m.arbitration_id, bytes(m.data).hex()))


# -- our controller, spacecan's responder ------------------------------------------------------


@pytest.fixture
def ours_theirs(peer_env):
    their = spacecan.Responder.from_json(
        {
            "interface": "socketcan",
            "channel_a": peer_env.channels[0],
            "channel_b": peer_env.channels[1],
            "node_id": 1,
            "heartbeat_period": HB,
            "max_miss_heartbeat": 3,
            "use_packets": True,
        }
    )
    got = types.SimpleNamespace(scet=[], utc=[], sync=[], switches=[])
    their.received_scet = lambda coarse, fine: got.scet.append((coarse, fine))
    their.received_utc = lambda day, ms, sub: got.utc.append((day, ms, sub))
    their.received_sync = lambda: got.sync.append(1)
    their.on_bus_switch = lambda: got.switches.append(their.get_active_bus())
    their.connect()
    services = spacecan.Services(their).from_file(peer_env.nodefile)
    their.start()
    peer_env.stops.append(their.disconnect)
    peer_env.stops.append(their.stop)
    ctrl = Controller(heartbeat_period=HB, timeout=0.3, retries=3)
    ctrl.add_node(1, NodeDefinition.from_dict(NODE))
    faults = BusFaults()
    ours = CanAdapter(ctrl, channels=peer_env.channels, faults=faults).start()
    peer_env.stops.append(ours.close)
    assert wait_until(lambda: ours.counters["tx"] > 0)
    return types.SimpleNamespace(
        ctrl=ctrl, ad=ours, faults=faults, their=their, services=services, got=got, env=peer_env
    )


def test_ping_frames_match_trace(ours_theirs):
    o = ours_theirs
    sniffed(o.env.sniff)
    req = o.ad.request(lambda now: o.ctrl.ping(1, now))
    assert req.status == COMPLETED and req.result is True and req.reports == [1, 7]
    frames = sniffed(o.env.sniff)
    assert frames == [
        (0x281, "00001101"),
        (0x301, "000001011101"),
        (0x301, "00001102"),
        (0x301, "000001071101"),
    ]


def test_parameter_report(ours_theirs):
    o = ours_theirs
    sniffed(o.env.sniff)
    req = o.ad.request(lambda now: o.ctrl.request_parameters(1, [1, 2, 3, 4], now))
    assert req.status == COMPLETED
    assert req.result == {1: 3, 2: 7.5, 3: 0x12345678, 4: -20}
    frames = sniffed(o.env.sniff)
    assert frames[:2] == [(0x281, "0100140104010203"), (0x281, "010104")]
    assert (0x301, "020234567804ffec") in frames
    req = o.ad.request(lambda now: o.ctrl.request_parameters(1, [9], now))
    assert req.status == REJECTED and req.reports == [2]


def test_one_shot_housekeeping(ours_theirs):
    o = ours_theirs
    req = o.ad.request(lambda now: o.ctrl.request_housekeeping(1, [1, 2], now))
    assert req.status == COMPLETED
    assert req.result == {1: {1: 3, 4: -20}, 2: {2: 7.5}}


def test_periodic_housekeeping(ours_theirs):
    o = ours_theirs
    req = o.ad.request(lambda now: o.ctrl.enable_housekeeping(1, [1], now))
    assert req.status == COMPLETED

    def reports():
        return [e for e in list(o.ad.events) if e.kind == ev.HOUSEKEEPING_REPORT]

    assert wait_until(lambda: len(reports()) >= 2, 4.0)  # spacecan ticks once a second
    assert reports()[0].values == {1: 3, 4: -20}
    req = o.ad.request(lambda now: o.ctrl.disable_housekeeping(1, [1], now))
    assert req.status == COMPLETED
    req = o.ad.request(lambda now: o.ctrl.enable_housekeeping(1, [7], now))
    assert req.status == REJECTED


@pytest.mark.filterwarnings("ignore::pytest.PytestUnhandledThreadExceptionWarning")
def test_function_call_known_upstream_defect(ours_theirs):
    """spacecan 0.8.1's responder raises TypeError for every 8,1 and never answers."""
    o = ours_theirs
    req = o.ad.request(lambda now: o.ctrl.call_function(1, 2, now, retries=0))
    assert req.status == TIMEOUT
    assert req.reports == []


@pytest.mark.filterwarnings("ignore::pytest.PytestUnhandledThreadExceptionWarning")
@pytest.mark.xfail(strict=True, reason="known upstream: spacecan 0.8.1 responder breaks on 8,1")
def test_function_call_completes(ours_theirs):
    o = ours_theirs
    req = o.ad.request(lambda now: o.ctrl.call_function(1, 1, now, {1: 1}, retries=0))
    assert req.status == COMPLETED


def test_set_parameter_extension_rejected_by_peer(ours_theirs):
    o = ours_theirs
    req = o.ad.request(lambda now: o.ctrl.set_parameters(1, {1: 9}, now))
    assert req.status == REJECTED  # spacecan knows service 20 but not subtype 3: (1,2)


def test_unknown_service_ignored_by_peer(ours_theirs):
    o = ours_theirs
    req = o.ad.request(lambda now: o.ctrl.request(1, 99, 1, b"", now, timeout=0.2, retries=0))
    assert req.status == TIMEOUT  # spacecan drops it silently; we do not hang


def test_time_frames(ours_theirs):
    o = ours_theirs
    sniffed(o.env.sniff)
    o.ad.call(lambda now: o.ctrl.send_scet(0x11223344, 0xAABBCC))
    o.ad.call(lambda now: o.ctrl.send_utc(0x1122, 0xAABBCCDD, 0xEEFF))
    o.ad.call(lambda now: o.ctrl.send_sync())
    assert wait_until(lambda: o.got.scet and o.got.utc and o.got.sync)
    assert o.got.scet == [(0x11223344, 0xAABBCC)]
    assert o.got.utc == [(0x1122, 0xAABBCCDD, 0xEEFF)]
    frames = sniffed(o.env.sniff)
    assert frames == [(0x180, "aabbcc11223344"), (0x200, "eeffaabbccdd1122"), (0x080, "")]


def test_commanded_bus_switch_followed_by_peer(ours_theirs):
    o = ours_theirs
    assert o.ad.request(lambda now: o.ctrl.ping(1, now)).status == COMPLETED
    o.ad.call(lambda now: o.ctrl.switch_bus(now))
    assert wait_until(lambda: o.got.switches == [1], 3.0)
    assert o.their.get_active_bus() == 1
    req = o.ad.request(lambda now: o.ctrl.ping(1, now))
    assert req.status == COMPLETED and req.bus == 1
    assert [e.kind for e in o.ad.events].count(ev.BUS_SWITCHED) == 1


def test_bus_a_dies_mid_command(ours_theirs):
    o = ours_theirs
    assert o.ad.request(lambda now: o.ctrl.ping(1, now)).status == COMPLETED
    o.faults.kill(0)
    req = o.ad.request(lambda now: o.ctrl.request_parameters(1, [4], now, retries=6))
    assert req.status == COMPLETED and req.result == {4: -20}
    assert req.bus == 1 and o.ctrl.active == 1
    assert wait_until(lambda: o.their.get_active_bus() == 1)
    sw = [e for e in o.ad.events if e.kind == ev.BUS_SWITCHED]
    assert sw and sw[0].old == 0 and sw[0].new == 1


# -- spacecan's controller, our responder ------------------------------------------------------


@pytest.fixture
def theirs_ours(peer_env):
    resp = Responder(1, NodeDefinition.from_dict(NODE), heartbeat_period=HB)
    calls = []
    resp.on_function = lambda fid, args: calls.append((fid, args))
    faults = BusFaults()
    ours = CanAdapter(resp, channels=peer_env.channels, faults=faults).start()
    peer_env.stops.append(ours.close)
    their = spacecan.Controller.from_json(
        {
            "interface": "socketcan",
            "channel_a": peer_env.channels[0],
            "channel_b": peer_env.channels[1],
            "heartbeat_period": HB,
            "use_packets": True,
        }
    )
    their.connect()
    services = spacecan.Services(their).from_file(peer_env.nodefile, node_id=1)
    got = types.SimpleNamespace(reports=[], pings=[], params=[], hk=[])
    services.request.received_report = lambda node, case, data: got.reports.append(
        (node, case, bytes(data or b""))
    )
    services.test.received_connection_test_report = lambda node: got.pings.append(node)
    services.parameter.received_parameter_value_report = lambda node, rep: got.params.append(rep)
    services.housekeeping.received_housekeeping_report = lambda node, rep, rid: got.hk.append(
        (rid, rep)
    )
    their.start()
    peer_env.stops.append(their.disconnect)
    peer_env.stops.append(their.stop)
    assert wait_until(lambda: resp.health[0].heartbeats > 0)
    return types.SimpleNamespace(
        resp=resp, ad=ours, their=their, services=services, got=got, calls=calls, env=peer_env
    )


def reports_for(got, service, subtype):
    return [
        case[1] for node, case, data in list(got.reports) if data[:2] == bytes((service, subtype))
    ]


def test_peer_ping_frames_match_trace(theirs_ours):
    t = theirs_ours
    sniffed(t.env.sniff)
    t.services.test.perform_connection_test(1)
    assert wait_until(lambda: t.got.pings == [1] and reports_for(t.got, 17, 1) == [1, 7])
    assert sniffed(t.env.sniff) == [
        (0x281, "00001101"),
        (0x301, "000001011101"),
        (0x301, "00001102"),
        (0x301, "000001071101"),
    ]


def test_peer_parameter_report(theirs_ours):
    t = theirs_ours
    t.services.parameter.request_parameter_report(1, [1, 2, 3, 4])
    assert wait_until(lambda: t.got.params)
    assert t.got.params[0] == {(1, 1): 3, (1, 2): 7.5, (1, 3): 0x12345678, (1, 4): -20}
    t.services.parameter.request_parameter_report(1, [9])
    assert wait_until(lambda: 2 in reports_for(t.got, 20, 1))


def test_peer_housekeeping(theirs_ours):
    t = theirs_ours
    t.services.housekeeping.request_hk_report(1, [1])
    assert wait_until(lambda: t.got.hk)
    assert t.got.hk[0] == ((1, 1), {(1, 1): 3, (1, 4): -20})
    t.services.housekeeping.enable_hk_report(1, [2])
    assert wait_until(lambda: len([h for h in t.got.hk if h[0] == (1, 2)]) >= 3, 3.0)
    t.services.housekeeping.disable_hk_report(1, [2])
    assert wait_until(lambda: reports_for(t.got, 3, 6) == [1, 7])
    assert not t.resp.nodedef.reports[2].enabled


def test_peer_function_call_works_with_our_responder(theirs_ours):
    t = theirs_ours
    t.services.function.perform(1, 1, {1: 1})
    assert wait_until(lambda: reports_for(t.got, 8, 1) == [1, 7])
    assert t.calls == [(1, {1: 1})]


def test_peer_unsupported_service_answered(theirs_ours):
    t = theirs_ours
    from spacecan.services.service_packet import ServicePacket

    t.services.send(ServicePacket(99, 1), 1)
    assert wait_until(lambda: reports_for(t.got, 99, 1) == [2])


def test_peer_time_frames(theirs_ours):
    t = theirs_ours
    t.their.send_scet(0x11223344, 0xAABBCC)
    t.their.send_utc(0x1122, 0xAABBCCDD, 0xEEFF)
    t.their.send_sync()
    assert wait_until(lambda: t.resp.utc is not None and t.resp.scet is not None)
    assert (t.resp.scet.coarse_time, t.resp.scet.fine_time) == (0x11223344, 0xAABBCC)
    assert (t.resp.utc.day, t.resp.utc.ms_of_day, t.resp.utc.sub_ms) == (
        0x1122,
        0xAABBCCDD,
        0xEEFF,
    )
    assert wait_until(lambda: any(e.kind == ev.SYNC for e in list(t.ad.events)))


def test_peer_bus_switch(theirs_ours):
    t = theirs_ours
    sniffed(t.env.sniff_b)
    t.their.switch_bus()
    # answered on B at once (we receive both buses), before we even follow the heartbeat
    t.services.test.perform_connection_test(1)
    assert wait_until(lambda: t.got.pings == [1])
    assert (0x301, "00001102") in sniffed(t.env.sniff_b)
    assert wait_until(lambda: t.resp.active == 1, 2.0)
    sw = [e for e in list(t.ad.events) if e.kind == ev.BUS_SWITCHED]
    assert sw[0].new == 1 and "heartbeat" in sw[0].reason
