"""The SpaceCAN part of `obsw demo`: the OBC's master and an equipment component, a responder,
two simulated CAN buses, and bus A failing."""

import sys
import time
import uuid

from obsw.spacecan import events as ev
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
        {"report_id": 1, "interval": 0.2, "enabled": False, "parameter_ids": [1, 2, 4]}
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
EQUIPMENT = "CpduN"
PERIOD = 0.1  # heartbeat period; the responder fails over after (3 + 1) periods


def run(out=print, interface="virtual", channels=None):
    """Run the demo (about two seconds) and print what happens; returns 0 on success.

    The OBC side is the SpaceCAN master and the equipment component of node 5 ("CpduN",
    generated from its node definition) on an interaction-layer node; the demo uses them
    through proxies, as any other process would. The node is a responder on its own thread.
    """
    from obsw.il.errors import ComponentError
    from obsw.spacecan.equipment import Equipment
    from obsw.spacecan.master import MASTER
    from obsw_host.spacecan.obc import ObcSpaceCan

    if channels is None:
        tag = uuid.uuid4().hex[:6]
        channels = ("demo_a_" + tag, "demo_b_" + tag)
    nodedef = NodeDefinition.from_dict(NODE)
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

    cpdu_eq = Equipment(EQUIPMENT, NODE_ID, NodeDefinition.from_dict(NODE, NODE_ID))
    obc = ObcSpaceCan(
        [cpdu_eq],
        interface=interface,
        channels=channels,
        transport=False,
        faults=faults,
        heartbeat_period=PERIOD,
        timeout=0.15,
        retries=4,
    )
    ctrl = obc.controller
    ra = CanAdapter(resp, interface=interface, channels=channels, faults=faults)
    obc.adapter.subscribe(note("controller"))
    ra.subscribe(note("responder node %d" % NODE_ID))
    master = obc.node.proxy(MASTER, timeout=5.0)
    cpdu = obc.node.proxy(cpdu_eq.interface, timeout=5.0)
    ok = True
    try:
        ra.start()
        obc.start()
        out(
            "SpaceCAN: controller (node 0) and responder node %d on %s channels %s (A) and %s (B)"
            % (NODE_ID, interface, channels[0], channels[1])
        )
        out(
            "  OBC side on the interaction layer: %s and %s (node %d, from its definition)"
            % (MASTER.name, EQUIPMENT, NODE_ID)
        )
        _wait_until(obc, lambda: resp.health[0].heartbeats >= 3, 2.0)
        out(
            "  heartbeat every %.1f s on bus A: responder has seen %d"
            % (PERIOD, resp.health[0].heartbeats)
        )

        rec = master.ping(NODE_ID).result(5.0)
        out(
            "  (17,1) ping node %d: %s, reports %s"
            % (NODE_ID, rec["status"], _reports(rec["reports"]))
        )
        ok &= rec["status"] == "completed"

        values = cpdu.request_parameters(None).result(5.0)
        out("  (20,1) %s.request_parameters(): %d values" % (EQUIPMENT, len(values)))
        for name in sorted(values):
            out("      %-15s = %r" % (name, values[name]))
        ok &= len(values) == len(NODE["parameters"])

        updates = []
        pending = cpdu.set_cpdu_line(1, True, on_status=lambda p, s, v: updates.append(v))
        rec = pending.result(5.0)
        out(
            "  (8,1) proxy call %s.set_cpdu_line(line=1, on=True): %s, reports %s;"
            " cpdu_lines now 0b%s"
            % (
                EQUIPMENT,
                rec["status"],
                _reports(rec["reports"]),
                _bin(resp.get_value("cpdu_lines")),
            )
        )
        steps = [u["status"] for u in updates if isinstance(u, dict) and "status" in u]
        out("      status updates through the interaction layer: %s" % " -> ".join(steps))
        ok &= rec["status"] == "completed"

        lines = cpdu.subscribe("cpdu_lines", length=16)
        cpdu.enable_housekeeping([1]).result(5.0)
        pub = lines.receive(timeout=3.0)
        out(
            "  (3,5) periodic report 1 on: attribute %s = 0b%s, fed by housekeeping"
            % (pub.name if pub else EQUIPMENT + ".cpdu_lines", _bin(pub.value) if pub else "?")
        )
        ok &= bool(pub) and pub.value == resp.get_value("cpdu_lines")
        cpdu.disable_housekeeping([1]).result(5.0)

        try:
            cpdu.set_cpdu_line(300, True).result(5.0)
        except ComponentError as e:
            out("  set_cpdu_line(line=300): ComponentError %s: %s" % (e.code, e.message))

        obc.adapter.call(lambda now: ctrl.send_scet(1000, 0x800000))
        _wait_until(obc, lambda: resp.scet is not None, 1.0)
        out("  SCET broadcast: responder time is now %s" % (resp.scet,))

        failovers = master.subscribe("bus_failover", length=8)
        out("  -- bus A fails (every frame on it is lost) --")
        t_kill = time.monotonic()
        faults.kill(0)
        rec = cpdu.set_cpdu_line(3, True).result(5.0)
        _wait_until(obc, lambda: resp.active == 1, 2.0)
        for side, e in switches:
            out(
                "  %s switched %s -> %s after %.2f s: %s"
                % (side, bus_name(e.old), bus_name(e.new), max(0.0, e.time - t_kill), e.reason)
            )
        pub = failovers.receive(timeout=1.0)
        if pub:
            out("  event %s: %s" % (pub.name, pub.value))
        out(
            "  set_cpdu_line(line=3, on=True) issued as A died: %s on bus %s after %d attempts;"
            " cpdu_lines now 0b%s"
            % (
                rec["status"],
                bus_name(rec["bus"]),
                rec["attempts"],
                _bin(resp.get_value("cpdu_lines")),
            )
        )
        ok &= rec["status"] == "completed"
        rec = master.ping(NODE_ID).result(5.0)
        out(
            "  (17,1) ping on bus %s: %s in one attempt: %s"
            % (bus_name(rec["bus"]), rec["status"], rec["attempts"] == 1)
        )
        ok &= rec["status"] == "completed"
        out("  %s.active_bus = %s" % (MASTER.name, bus_name(master.active_bus)))
        for s in master.bus_status:
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
        obc.close()
        ra.close()
    return 0 if ok else 1


def _wait_until(obc, predicate, timeout):
    """Serve the OBC side until predicate() is true or timeout seconds passed."""
    end = time.monotonic() + timeout
    while not predicate() and time.monotonic() < end:
        obc.wait(0.01)
    return predicate()


def _reports(reports):
    names = {1: "accepted", 2: "rejected", 7: "completed", 8: "failed"}
    return "/".join(names.get(r, str(r)) for r in reports) or "none"


def _bin(v):
    s = ""
    for i in range(4):
        s = ("1" if v >> i & 1 else "0") + s
    return s


if __name__ == "__main__":
    sys.exit(run())
