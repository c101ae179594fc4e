"""SpaceCAN over python-can virtual channels through the host adapter, with fault injection."""

import importlib.util
import pathlib
import uuid

import can as can
import pytest
from obsw.spacecan import events as ev  # noqa: E402
from obsw.spacecan.controller import COMPLETED, TIMEOUT, Controller, FailoverPolicy  # noqa: E402
from obsw.spacecan.nodedef import NodeDefinition  # noqa: E402
from obsw.spacecan.responder import Responder  # noqa: E402
from obsw_host.spacecan.adapter import AdapterError, BusFaults, CanAdapter  # noqa: E402

NODE = {
    "parameters": [
        {"parameter_id": 1, "parameter_name": "mode", "encoding": "u8", "value": 3},
        {"parameter_id": 2, "parameter_name": "temp", "encoding": "i16", "value": -20},
    ],
    "housekeeping_reports": [
        {"report_id": 1, "interval": 0.1, "enabled": False, "parameter_ids": [1, 2]}
    ],
    "functions": [
        {
            "function_id": 1,
            "function_name": "fire",
            "arguments": [{"argument_id": 1, "argument_name": "n", "encoding": "u16"}],
        }
    ],
}


@pytest.fixture
def pair():
    tag = uuid.uuid4().hex[:8]
    channels = ("hA" + tag, "hB" + tag)
    faults = BusFaults()
    ctrl = Controller(heartbeat_period=0.05, timeout=0.1, retries=3)
    ctrl.add_node(1, NodeDefinition.from_dict(NODE))
    resp = Responder(1, NodeDefinition.from_dict(NODE), heartbeat_period=0.05)
    fired = []
    resp.on_function = lambda fid, args: fired.append((fid, args))
    ca = CanAdapter(ctrl, channels=channels, faults=faults).start()
    ra = CanAdapter(resp, channels=channels, faults=faults).start()
    yield ctrl, resp, ca, ra, faults, fired
    ca.close()
    ra.close()


def test_services_over_virtual_can(pair):
    ctrl, resp, ca, ra, faults, fired = pair
    assert ca.request(lambda now: ctrl.ping(1, now)).status == COMPLETED
    req = ca.request(lambda now: ctrl.request_parameters(1, [1, 2], now))
    assert req.result == {1: 3, 2: -20}
    req = ca.request(lambda now: ctrl.call_function(1, 1, now, {1: 500}))
    assert req.status == COMPLETED and fired == [(1, {1: 500})]
    req = ca.request(lambda now: ctrl.set_parameters(1, {1: 4}, now))
    assert req.status == COMPLETED and resp.get_value(1) == 4
    assert ca.request(lambda now: ctrl.enable_housekeeping(1, [1], now)).status == COMPLETED
    assert ca.wait_for(
        lambda: sum(e.kind == ev.HOUSEKEEPING_REPORT for e in list(ca.events)) >= 2, 3.0
    )


def test_bus_a_dies_mid_command(pair):
    ctrl, resp, ca, ra, faults, fired = pair
    assert ca.request(lambda now: ctrl.ping(1, now)).status == COMPLETED

    def start(now):
        req = ctrl.call_function(1, 1, now, {1: 7})
        faults.kill(0)  # the frames of this command never make it onto bus A
        return req

    req = ca.request(start)
    assert req.status == COMPLETED and req.bus == 1
    assert fired == [(1, {1: 7})]
    assert ca.wait_for(lambda: resp.active == 1, 2.0)
    kinds = [e.kind for e in list(ca.events)]
    assert ev.BUS_SWITCHED in kinds


def test_dropped_and_corrupted_frames_recovered(pair):
    ctrl, resp, ca, ra, faults, fired = pair
    faults.drop(0, count=1)
    req = ca.request(lambda now: ctrl.request_parameters(1, [1, 2], now))
    assert req.status == COMPLETED
    faults.corrupt(0, count=1)
    req = ca.request(lambda now: ctrl.request_parameters(1, [1, 2], now))
    assert req.status == COMPLETED and req.result == {1: 3, 2: -20}
    assert faults.counters["dropped"] >= 1 and faults.counters["corrupted"] == 1


def test_silent_node_times_out(pair):
    ctrl, resp, ca, ra, faults, fired = pair
    ctrl.add_node(9)
    req = ca.request(lambda now: ctrl.ping(9, now), timeout=5.0)
    assert req.status == TIMEOUT and req.attempts == 4


def test_transmit_errors_fail_over():
    tag = uuid.uuid4().hex[:8]
    faults = BusFaults()
    ctrl = Controller(heartbeat_period=0.02, policy=FailoverPolicy(max_tx_errors=2))
    faults.kill(0, tx_errors=True)
    ca = CanAdapter(ctrl, channels=("tA" + tag, "tB" + tag), faults=faults).start()
    try:
        assert ca.wait_for(lambda: ctrl.active == 1, 2.0)
        assert ca.counters["tx_errors"] >= 2
        assert any(
            "transmit errors" in e.reason for e in list(ca.events) if e.kind == ev.BUS_SWITCHED
        )
    finally:
        ca.close()


def test_call_errors_propagate_and_loop_survives(pair):
    ctrl, resp, ca, ra, faults, fired = pair
    with pytest.raises(ValueError):
        ca.call(lambda now: ctrl.ping(0, now))
    assert ca.request(lambda now: ctrl.ping(1, now)).status == COMPLETED


def test_call_without_loop_runs_inline():
    ctrl = Controller()
    ad = CanAdapter(ctrl, buses=[None, None])
    assert ad.call(lambda now: now > 0)
    with pytest.raises(AdapterError):
        ad.request(lambda now: ctrl.ping(1, now), timeout=0.01)


class FakeCan:
    """Just enough of pyb.CAN for the board shim: a FIFO in, a list out."""

    def __init__(self, fail=False):
        self.rx = []
        self.tx = []
        self.fail = fail

    def any(self, fifo):
        return len(self.rx)

    def recv(self, fifo, timeout=0):
        return self.rx.pop(0)

    def send(self, data, can_id, timeout=0):
        if self.fail:
            raise OSError(110)
        self.tx.append((can_id, bytes(data)))


def test_pyb_shim_with_fake_can():
    path = pathlib.Path(__file__).resolve().parents[2] / "boards" / "common" / "spacecan_pyb.py"
    spec = importlib.util.spec_from_file_location("spacecan_pyb", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    resp = Responder(1, NodeDefinition.from_dict(NODE))
    a, b = FakeCan(), FakeCan(fail=True)
    t = [0.0]
    drv = mod.PybCanDriver(resp, a, b, clock=lambda: t[0])
    a.rx.append((0x281, False, False, 0, b"\x00\x00\x11\x01"))  # current firmware tuple
    a.rx.append((0x700, 0, 0, b""))  # older firmware tuple
    drv.step()
    assert a.tx == [
        (0x301, bytes.fromhex("000001011101")),
        (0x301, bytes.fromhex("00001102")),
        (0x301, bytes.fromhex("000001071101")),
    ]
    assert resp.health[0].heartbeats == 1
    resp.send_raw(b"\x01", bus=1)
    drv.step()
    assert drv.counters["tx_errors"] == 1 and resp.health[1].tx_errors == 1
    t[0] = 10.0
    assert drv.next_wait_ms(10) == 0


def test_udp_multicast_buses_stay_apart():
    # Two multicast groups on one port reach every socket bound to that port: the adapter must
    # give bus B a port of its own, or a frame on bus A would also arrive on bus B.
    import can

    groups = ("239.74.163.12", "239.74.163.13")
    adapter = CanAdapter(Controller(), interface="udp_multicast", channels=groups)
    listeners = [
        can.Bus(interface="udp_multicast", channel=g, port=43113 + i) for i, g in enumerate(groups)
    ]
    try:
        adapter.buses[0].send(can.Message(arbitration_id=0x301, data=b"A", is_extended_id=False))
        got_a = listeners[0].recv(2.0)
        got_b = listeners[1].recv(0.3)
    finally:
        for bus in listeners:
            bus.shutdown()
        adapter.close()
    assert got_a is not None and bytes(got_a.data) == b"A"
    assert got_b is None
