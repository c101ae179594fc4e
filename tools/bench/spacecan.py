"""SpaceCAN benchmark: obsw's core against spacecan 0.8.1, measured in the same run.

Cases: fragmentation + reassembly of 64-byte packets; frames a responder serves (ping, 1 frame
in, 3 out); controller round trips (ping) through controller and responder joined in memory;
responder failover after heartbeat loss, against the configured (max_miss + 1) * period.
`--quick` runs fewer, shorter repetitions; `--json` prints the common bench JSON.
"""

import argparse
import importlib.util
import json
import pathlib
import sys
import threading
import time
import uuid

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
# this file is named like the peer package: keep its folder off the path so `import spacecan`
# finds LibreCube's spacecan
sys.path[:] = [p for p in sys.path if pathlib.Path(p or ".").resolve() != HERE]
sys.path[:0] = [str(ROOT / "micropython"), str(ROOT / "host")]
_spec = importlib.util.spec_from_file_location("bench_measure", HERE / "measure.py")
measure = importlib.util.module_from_spec(_spec)  # this folder's shared helper, by its file
_spec.loader.exec_module(measure)

from obsw.spacecan.controller import Controller  # noqa: E402
from obsw.spacecan.fragment import Reassembler, split  # noqa: E402
from obsw.spacecan.nodedef import NodeDefinition  # noqa: E402
from obsw.spacecan.responder import Responder  # noqa: E402
from obsw.spacecan.sim import SimNetwork  # noqa: E402

NODE = {
    "parameters": [{"parameter_id": 1, "parameter_name": "a", "encoding": "u8", "value": 3}],
    "housekeeping_reports": [],
    "functions": [],
}
PAYLOAD = bytes(range(64))


def timed(fn, n):
    t = time.perf_counter()
    fn(n)
    return n / (time.perf_counter() - t)


# -- fragmentation -----------------------------------------------------------------------------


def ours_fragment(n):
    r = Reassembler()
    push = r.push
    for _ in range(n):
        for f in split(PAYLOAD):
            p = push(0x281, f, 0.0)
    assert p == PAYLOAD


def theirs_fragment(n):
    from spacecan.primitives.can_frame import CanFrame
    from spacecan.primitives.packet import Packet, PacketAssembler

    a = PacketAssembler(None)
    for _ in range(n):
        for f in Packet(PAYLOAD).split():
            p = a.process_frame(CanFrame(0x281, f))
    assert bytes(p.data) == PAYLOAD


# -- responder frames --------------------------------------------------------------------------


def ours_responder(n):
    r = Responder(1, NodeDefinition.from_dict(NODE), heartbeat_period=0)
    frame = b"\x00\x00\x11\x01"
    for i in range(n):
        r.receive(0, 0x281, frame, 0.0)
        if i & 63 == 0:
            r.take_frames()
            r.take_events()
    r.take_frames()


class _Net:
    def __init__(self, on_send):
        self.send = on_send


def theirs_responder(n):
    import spacecan
    from spacecan.primitives.can_frame import CanFrame

    got = [0]
    done = threading.Event()

    def on_send(frame):
        got[0] += 1
        if got[0] == 3 * n:
            done.set()

    resp = spacecan.Responder("socketcan", "a", "b", 1, heartbeat_period=0, use_packets=True)
    resp.network = _Net(on_send)
    spacecan.Services(resp).parameter.add_parameters_from_dict(NODE)
    for _ in range(n):
        resp.received_frame(CanFrame(0x281, b"\x00\x00\x11\x01"))
    if not done.wait(60):
        raise RuntimeError("spacecan responder answered %d of %d frames" % (got[0], 3 * n))


# -- controller round trips --------------------------------------------------------------------


def ours_round_trips(n):
    c = Controller(heartbeat_period=0)
    c.add_node(1)
    r = Responder(1, NodeDefinition.from_dict(NODE), heartbeat_period=0)
    net = SimNetwork().attach(c, r)
    for _ in range(n):
        req = c.ping(1, net.now)
        net.pump()
        c.take_events()
        r.take_events()
    assert req.ok


def theirs_round_trips(n):
    import spacecan

    c = spacecan.Controller("socketcan", "a", "b", heartbeat_period=0, use_packets=True)
    r = spacecan.Responder("socketcan", "a", "b", 1, heartbeat_period=0, use_packets=True)
    c.network = _Net(lambda frame: r.received_frame(frame))
    r.network = _Net(lambda frame: c.received_frame(frame))
    cs = spacecan.Services(c)
    spacecan.Services(r)
    done = threading.Event()
    cs.request.received_success_completion_report = lambda node, data: done.set()
    for _ in range(n):
        done.clear()
        cs.test.perform_connection_test(1)
        if not done.wait(10):
            raise RuntimeError("spacecan ping did not complete")


# -- failover ----------------------------------------------------------------------------------


def ours_failover(period, max_miss, commanded=False):
    """Seconds from the last heartbeat (or from the switch command) to the responder's switch."""
    from obsw.spacecan import events as ev
    from obsw_host.spacecan.adapter import BusFaults, CanAdapter

    tag = uuid.uuid4().hex[:6]
    ch = ("bA" + tag, "bB" + tag)
    ctrl = Controller(heartbeat_period=period)
    resp = Responder(
        1, NodeDefinition.from_dict(NODE), heartbeat_period=period, max_miss_heartbeat=max_miss
    )
    switched = []
    ra = CanAdapter(resp, channels=ch, faults=BusFaults())
    ra.subscribe(lambda e: e.kind == ev.BUS_SWITCHED and switched.append(e.time))
    ca = CanAdapter(ctrl, channels=ch)
    with ra, ca:
        ra.wait_for(lambda: resp.health[0].heartbeats >= 3, 5)
        t = time.monotonic()
        if commanded:
            ca.call(lambda now: ctrl.switch_bus(now))
        else:
            ca.stop()  # the controller falls silent
        ra.wait_for(lambda: switched, 10 * period * (max_miss + 1))
        if not commanded:
            t = resp.health[0].last_heartbeat
        return switched[0] - t


def theirs_failover(period, max_miss, commanded=False):
    """The same for spacecan's controller and responder (its own threads and timers)."""
    import types

    import can
    import spacecan
    import spacecan.transport.socketcan as sc_socket

    sc_socket.can = types.SimpleNamespace(
        Bus=lambda interface, channel: can.Bus(interface="virtual", channel=channel),
        Message=can.Message,
        exceptions=can.exceptions,
    )
    tag = uuid.uuid4().hex[:6]
    cfg = {
        "interface": "socketcan",
        "channel_a": "sA" + tag,
        "channel_b": "sB" + tag,
        "heartbeat_period": period,
    }
    c = spacecan.Controller.from_json(cfg)
    r = spacecan.Responder.from_json(dict(cfg, node_id=1, max_miss_heartbeat=max_miss))
    # spacecan's switch from its timer thread races stop(): keep its thread errors off the table
    threading.excepthook = lambda args: None
    switched = threading.Event()
    times = {}
    r.on_bus_switch = lambda: (times.setdefault("switch", time.monotonic()), switched.set())
    r.received_heartbeat = lambda: times.__setitem__("hb", time.monotonic())
    c.connect()
    r.connect()
    r.start()
    c.start()
    time.sleep(3 * period)
    t = time.monotonic()
    if commanded:
        c.switch_bus()
    else:
        c.stop()
    switched.wait(10 * period * (max_miss + 1))
    if not commanded:
        t = times["hb"]
        c.start()  # so that the one stop() below finds it running
    c.stop()
    r.stop()
    c.disconnect()
    r.disconnect()
    for th in threading.enumerate():
        if isinstance(th, threading.Timer):
            th.cancel()
    return times["switch"] - t


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--quick", action="store_true")
    a = ap.parse_args(argv)
    runs, n = (3, 2000) if a.quick else (5, 10000)
    try:
        import spacecan  # noqa: F401

        peer = True
    except ImportError:
        peer = False
    rows = []

    def pair(case, unit, ours, theirs, hib=True):
        rows.append(
            {"case": case, "impl": "obsw", "value": ours, "unit": unit, "higher_is_better": hib}
        )
        if theirs is not None:
            rows.append(
                {
                    "case": case,
                    "impl": "spacecan",
                    "value": theirs,
                    "unit": unit,
                    "higher_is_better": hib,
                }
            )

    m = measure.median_of(lambda: timed(ours_fragment, n), runs)
    t = measure.median_of(lambda: timed(theirs_fragment, n), runs) if peer else None
    pair("fragment+reassemble 64 B", "packets/s", m, t)
    m = measure.median_of(lambda: timed(ours_responder, n) * 4, runs)
    t = measure.median_of(lambda: timed(theirs_responder, n // 4) * 4, runs) if peer else None
    pair("responder ping frames (1 in, 3 out)", "frames/s", m, t)
    m = measure.median_of(lambda: timed(ours_round_trips, n), runs)
    t = measure.median_of(lambda: timed(theirs_round_trips, n // 10), runs) if peer else None
    pair("controller ping round trips", "round trips/s", m, t)
    period, max_miss = 0.05, 3
    deadline = period * (max_miss + 1)
    fr = 3 if a.quick else 5
    m = measure.median_of(lambda: ours_failover(period, max_miss), fr)
    t = measure.median_of(lambda: theirs_failover(period, max_miss), fr) if peer else None
    pair(
        "failover after heartbeat loss / configured deadline",
        "ratio",
        m / deadline,
        None if t is None else t / deadline,
        hib=False,
    )
    rows.append(
        {
            "case": "failover after heartbeat loss / configured deadline",
            "impl": "reference",
            "value": 1.0,
            "unit": "ratio",
            "higher_is_better": False,
        }
    )
    m = measure.median_of(lambda: ours_failover(period, max_miss, True), fr)
    t = measure.median_of(lambda: theirs_failover(period, max_miss, True), fr) if peer else None
    pair(
        "responder follows commanded switch / configured deadline",
        "ratio",
        m / deadline,
        None if t is None else t / deadline,
        hib=False,
    )
    if a.json:
        print(json.dumps({"bench": "spacecan", "rows": rows}))
        return 0
    print("%-52s %14s %14s %8s  %s" % ("case", "obsw", "spacecan", "ratio", "unit"))
    cases = []
    for r in rows:
        if r["case"] not in cases:
            cases.append(r["case"])
    for c in cases:
        o = next(r for r in rows if r["case"] == c and r["impl"] == "obsw")
        p = next((r for r in rows if r["case"] == c and r["impl"] == "spacecan"), None)
        ratio = "" if p is None or not p["value"] else "%.2f" % (o["value"] / p["value"])
        print(
            "%-52s %14.2f %14s %8s  %s"
            % (c, o["value"], "-" if p is None else "%.2f" % p["value"], ratio, o["unit"])
        )
    return 0


def _exit(code):
    # spacecan's receive threads are not daemons and can outlive its stop() after a bus switch
    # (its timer race): leave without waiting for them once our output is out
    sys.stdout.flush()
    lingering = [
        t for t in threading.enumerate() if not t.daemon and t is not threading.current_thread()
    ]
    if lingering:
        import os

        os._exit(code)
    sys.exit(code)


if __name__ == "__main__":
    _exit(main())
