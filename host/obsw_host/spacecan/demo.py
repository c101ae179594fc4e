"""The SpaceCAN part of `obsw demo`: a controller and a responder on two simulated CAN buses."""

import time
import uuid

from obsw.spacecan import events as ev
from obsw.spacecan.controller import Controller
from obsw.spacecan.ids import bus_name
from obsw.spacecan.nodedef import NodeDefinition
from obsw.spacecan.responder import Responder

from obsw_host.spacecan.adapter import BusFaults, CanAdapter

NODE = {
    "parameters": [
        {"parameter_id": 1, "parameter_name": "cpdu_lines", "encoding": "u8", "value": 0b0101},
        {"parameter_id": 2, "parameter_name": "board_temp", "encoding": "f32", "value": 21.5},
        {"parameter_id": 3, "parameter_name": "uptime_s", "encoding": "u32", "value": 4242},
        {"parameter_id": 4, "parameter_name": "bus_voltage_mv", "encoding": "i16", "value": 5012},
    ],
    "housekeeping_reports": [
        {"report_id": 1, "interval": 1.0, "enabled": False, "parameter_ids": [1, 2, 4]}
    ],
    "functions": [
        {
            "function_id": 1,
            "function_name": "set_cpdu_line",
            "arguments": [
                {"argument_id": 1, "argument_name": "line", "encoding": "u8"},
                {"argument_id": 2, "argument_name": "on", "encoding": "bool"},
            ],
        }
    ],
}
NODE_ID = 5
PERIOD = 0.1  # heartbeat period; the responder fails over after (3 + 1) periods


def run(out=print, interface="virtual", channels=None):
    """Run the demo (about two seconds) and print what happens; returns 0 on success."""
    if channels is None:
        tag = uuid.uuid4().hex[:6]
        channels = ("demo_a_" + tag, "demo_b_" + tag)
    nodedef = NodeDefinition.from_dict(NODE)
    ctrl = Controller(heartbeat_period=PERIOD, timeout=0.15, retries=4)
    ctrl.add_node(NODE_ID, NodeDefinition.from_dict(NODE))
    resp = Responder(NODE_ID, nodedef, heartbeat_period=PERIOD, max_miss_heartbeat=3)

    def set_line(fid, args):
        lines = resp.get_value("cpdu_lines")
        bit = 1 << args[1]
        resp.set_value("cpdu_lines", (lines | bit) if args[2] else (lines & ~bit))
        return True

    resp.on_function = set_line
    faults = BusFaults()
    t0 = time.monotonic()
    switches = []

    def note(side):
        def listener(e):
            if e.kind == ev.BUS_SWITCHED:
                switches.append((side, e))

        return listener

    ca = CanAdapter(ctrl, interface=interface, channels=channels, faults=faults)
    ra = CanAdapter(resp, interface=interface, channels=channels, faults=faults)
    ca.subscribe(note("controller"))
    ra.subscribe(note("responder node %d" % NODE_ID))
    ok = True
    try:
        ra.start()
        ca.start()
        out(
            "SpaceCAN: controller (node 0) and responder node %d on %s channels %s (A) and %s (B)"
            % (NODE_ID, interface, channels[0], channels[1])
        )
        ca.wait_for(lambda: resp.health[0].heartbeats >= 3, 2.0)
        out(
            "  heartbeat every %.1f s on bus A: responder has seen %d"
            % (PERIOD, resp.health[0].heartbeats)
        )

        req = ca.request(lambda now: ctrl.ping(NODE_ID, now))
        out("  (17,1) ping node %d: %s, reports %s" % (NODE_ID, req.status, _reports(req)))
        ok &= req.ok

        req = ca.request(lambda now: ctrl.request_parameters(NODE_ID, [1, 2, 3, 4], now))
        out("  (20,1) parameters: %s" % req.status)
        for pid, value in sorted((req.result or {}).items()):
            out("      %-15s = %r" % (nodedef.parameters[pid].name, value))
        ok &= req.ok

        req = ca.request(lambda now: ctrl.call_function(NODE_ID, 1, {1: 1, 2: True}, now))
        out(
            "  (8,1) set_cpdu_line(line=1, on=True): %s, reports %s; cpdu_lines now 0b%s"
            % (req.status, _reports(req), _bin(resp.get_value("cpdu_lines")))
        )
        ok &= req.ok

        req = ca.request(lambda now: ctrl.request_housekeeping(NODE_ID, [1], now))
        hk = (req.result or {}).get(1, {})
        out(
            "  (3,27) housekeeping report 1: %s"
            % ", ".join("%s=%r" % (nodedef.parameters[p].name, v) for p, v in sorted(hk.items()))
        )
        ok &= req.ok

        ca.call(lambda now: ctrl.send_scet(1000, 0x800000))
        ca.wait_for(lambda: resp.scet is not None, 1.0)
        out("  SCET broadcast: responder time is now %s" % (resp.scet,))

        out("  -- bus A fails (every frame on it is lost) --")
        t_kill = time.monotonic()
        faults.kill(0)
        req = ca.request(lambda now: ctrl.request_parameters(NODE_ID, [3], now))
        ca.wait_for(lambda: resp.active == 1, 2.0)
        for side, e in switches:
            out(
                "  %s switched %s -> %s after %.2f s: %s"
                % (side, bus_name(e.old), bus_name(e.new), max(0.0, e.time - t_kill), e.reason)
            )
        out(
            "  (20,1) issued as A died: %s on bus %s after %d attempts, uptime_s=%r"
            % (req.status, bus_name(req.bus), req.attempts, (req.result or {}).get(3))
        )
        ok &= req.ok
        req = ca.request(lambda now: ctrl.ping(NODE_ID, now))
        out(
            "  (17,1) ping on bus %s: %s in one attempt: %s"
            % (bus_name(ctrl.active), req.status, req.attempts == 1)
        )
        ok &= req.ok
        status = ca.call(lambda now: ctrl.bus_status(now))
        for s in status:
            out(
                "  bus %s%s: %s, %d frames received, %d sent"
                % (
                    bus_name(s["bus"]),
                    " (active)" if s["active"] else "",
                    s["state"],
                    s["rx_frames"],
                    s["tx_frames"],
                )
            )
        out("SpaceCAN demo %s in %.1f s" % ("done" if ok else "FAILED", time.monotonic() - t0))
    finally:
        ca.close()
        ra.close()
    return 0 if ok else 1


def _reports(req):
    names = {1: "accepted", 2: "rejected", 7: "completed", 8: "failed"}
    return "/".join(names.get(r, str(r)) for r in req.reports) or "none"


def _bin(v):
    s = ""
    for i in range(4):
        s = ("1" if v >> i & 1 else "0") + s
    return s
