"""The SpaceCAN master as an interaction-layer component: its interface, requests as
asynchronous operations with status updates, typed errors, reports and bus failover as events,
on the simulated bus and clock."""

import unittest

from obsw.il.errors import ComponentError
from obsw.il.interface import DATA, LOW, MEDIUM, check_unique_ids
from obsw.spacecan import events as ev
from obsw.spacecan.controller import Controller
from obsw.spacecan.master import BAD_REQUEST, MASTER, MASTER_ID, SpaceCanMaster, record
from obsw.spacecan.responder import Responder
from obsw.spacecan.sim import SimNetwork
from spacecan_obc_sim import NODE, WAIT, Obc, definition, drain, manual


class TestInterface(unittest.TestCase):
    def test_declared_once_with_fixed_ids(self):
        self.assertEqual((MASTER.name, MASTER.id), ("SpaceCanMaster", MASTER_ID))
        ids = {}
        for name in (
            "send_command",
            "call_function",
            "request_parameters",
            "set_parameters",
            "ping",
            "switch_bus",
        ):
            op = MASTER.member(name)
            self.assertIsNotNone(op)
            ids[name] = op.id
        self.assertEqual(ids["call_function"], 17)
        self.assertEqual(MASTER.member(17).name, "call_function")
        self.assertTrue(MASTER.member("call_function").asynchronous)
        self.assertFalse(MASTER.member("switch_bus").asynchronous)
        for name in ("active_bus", "bus_a_state", "bus_b_state", "rx_frames", "tx_frames"):
            self.assertEqual(MASTER.member(name).kind, DATA)
        self.assertEqual(MASTER.member("verification_failure").severity, LOW)
        self.assertEqual(MASTER.member("bus_failover").severity, MEDIUM)
        every = [m.id for m in MASTER.members.values()]
        self.assertEqual(len(every), len(set(every)))
        check_unique_ids([MASTER])


class TestRequests(unittest.TestCase):
    def test_ping_completes_with_status_updates(self):
        obc = Obc()
        updates = []
        p = obc.proxy.ping(NODE, on_status=lambda p, state, value: updates.append(value))
        rec = p.result(WAIT)
        self.assertEqual(rec["status"], "completed")
        self.assertIs(rec["result"], True)
        self.assertEqual(rec["reports"], [1, 7])
        self.assertEqual((rec["node"], rec["service"], rec["subtype"]), (NODE, 17, 1))
        states = [u["status"] for u in updates if isinstance(u, dict) and "attempt" in u]
        self.assertEqual(states, ["sent", "accepted"])
        self.assertEqual(obc.proxy.pending_requests, 0)

    def test_call_function_goes_out_as_service_8(self):
        obc = Obc()
        rec = obc.proxy.call_function(NODE, 2, {1: 3, 2: 250}).result(WAIT)
        self.assertEqual(rec["status"], "completed")
        self.assertEqual(obc.calls, [(2, {1: 3, 2: 250})])
        bus, data = obc.requests_to(NODE)[0]
        self.assertEqual(bus, 0)
        self.assertEqual(data[2:4], bytes((8, 1)))  # after the 2-byte fragment header
        self.assertEqual(data[4], 2)

    def test_parameters_request_and_set(self):
        obc = Obc()
        reports = obc.proxy.subscribe("parameter_report")
        rec = obc.proxy.request_parameters(NODE, [1, 3]).result(WAIT)
        self.assertEqual(rec["result"], {1: 0, 3: 5020})
        obc.run(0.1)
        self.assertEqual(drain(reports)[0].value, {"node": NODE, "values": {1: 0, 3: 5020}})
        rec = obc.proxy.set_parameters(NODE, {1: 0x0FF}).result(WAIT)
        self.assertEqual(rec["reports"], [1, 7])
        self.assertEqual(obc.resp.get_value(1), 0x0FF)

    def test_send_command_and_housekeeping_operations(self):
        obc = Obc()
        rec = obc.proxy.send_command(NODE, 17, 1, b"").result(WAIT)
        self.assertIs(rec["result"], True)
        rec = obc.proxy.request_housekeeping(NODE, [2]).result(WAIT)
        self.assertEqual(rec["result"], {2: {3: 5020}})
        reports = obc.proxy.subscribe("housekeeping_report", length=16)
        obc.proxy.enable_housekeeping(NODE, [1]).result(WAIT)
        obc.run(3.5)
        got = drain(reports)
        self.assertEqual(len(got), 3)
        self.assertEqual(got[0].value, {"node": NODE, "report_id": 1, "values": {1: 0, 2: 24.5}})
        obc.proxy.disable_housekeeping(NODE, [1]).result(WAIT)
        obc.run(3.0)
        self.assertEqual(drain(reports), [])


class TestErrors(unittest.TestCase):
    def test_silent_node_gives_timeout_error(self):
        obc = Obc(responder=False, policy=manual())
        timeouts = obc.proxy.subscribe("request_timeout")
        p = obc.proxy.ping(9)
        with self.assertRaises(ComponentError) as cm:
            p.result(WAIT)
        e = cm.exception
        self.assertEqual(e.code, "TIMEOUT")
        self.assertEqual((e.data["node"], e.data["status"], e.data["attempts"]), (9, "timeout", 3))
        self.assertEqual(e.target, "SpaceCanMaster.ping")
        self.assertAlmostEqual(obc.net.now, 0.6, 6)  # three attempts of 0.2 s, not a hang
        obc.run(0.1)
        ev_ = drain(timeouts)[0].value
        self.assertEqual((ev_["node"], ev_["service"], ev_["attempts"]), (9, 17, 3))

    def test_rejected_and_failed(self):
        obc = Obc()
        failures = obc.proxy.subscribe("verification_failure")
        with self.assertRaises(ComponentError) as cm:
            obc.proxy.call_function(NODE, 9, None).result(WAIT)
        self.assertEqual(cm.exception.code, "REJECTED")
        self.assertEqual(cm.exception.data["reports"], [2])
        with self.assertRaises(ComponentError) as cm:
            obc.proxy.call_function(NODE, 3, None).result(WAIT)
        self.assertEqual(cm.exception.code, "FAILED")
        self.assertEqual(cm.exception.data["reports"], [1, 8])
        obc.run(0.1)
        got = [p.value for p in drain(failures)]
        self.assertEqual(
            got,
            [
                {"node": NODE, "service": 8, "subtype": 1, "report": 2, "matched": True},
                {"node": NODE, "service": 8, "subtype": 1, "report": 8, "matched": True},
            ],
        )

    def test_bad_requests_refused_before_sending(self):
        obc = Obc()
        before = len(obc.bus_frames())
        for call in (
            lambda: obc.proxy.ping(200),  # node ids are 1..127
            lambda: obc.proxy.set_parameters(9, {1: 1}),  # no definition for node 9
            lambda: obc.proxy.set_parameters(NODE, {1: -1}),  # u16
            lambda: obc.proxy.call_function(NODE, 2, {7: 1}),  # no argument 7
            lambda: obc.proxy.call_function(NODE, 2, [1, 2]),  # args are a dict
            lambda: obc.proxy.send_command(NODE, 17, 1, 5),  # data are bytes
        ):
            with self.assertRaises(ComponentError) as cm:
                call().result(WAIT)
            self.assertEqual(cm.exception.code, BAD_REQUEST)
        self.assertEqual(len(obc.bus_frames()), before)
        self.assertEqual(obc.master._jobs, {})


class TestBuses(unittest.TestCase):
    def test_bus_failure_mid_command_completes_on_b(self):
        obc = Obc(retries=3)
        failovers = obc.proxy.subscribe("bus_failover")
        active = obc.proxy.subscribe("active_bus")
        self.assertEqual(obc.proxy.ping(NODE).result(WAIT)["bus"], 0)
        updates = []
        p = obc.proxy.call_function(
            NODE, 1, {1: 0x3C}, on_status=lambda p, s, v: updates.append(v)
        )
        obc.node.poll()  # the master has sent it on bus A ...
        self.assertEqual(obc.master.pending_requests, 1)
        obc.net.kill(0)  # ... and bus A dies before a frame gets through
        rec = p.result(WAIT)
        self.assertEqual((rec["status"], rec["bus"]), ("completed", 1))
        self.assertEqual(obc.calls, [(1, {1: 0x3C})])  # performed once, nothing lost
        self.assertEqual(obc.resp.get_value("state_bits"), 0x3C)
        buses = [u["bus"] for u in updates if isinstance(u, dict) and "bus" in u]
        self.assertEqual(buses[0], 0)
        self.assertEqual(buses[-1], 1)
        obc.run(0.1)
        self.assertEqual(drain(failovers)[0].value["new"], "B")
        self.assertEqual(drain(active)[-1].value, 1)
        self.assertEqual(obc.proxy.active_bus, 1)
        self.assertEqual(obc.proxy.bus_switches, 1)

    def test_switch_bus_operation(self):
        obc = Obc()
        failovers = obc.proxy.subscribe("bus_failover")
        self.assertEqual(obc.proxy.switch_bus("B"), 1)
        self.assertEqual(obc.proxy.active_bus, 1)
        self.assertEqual(obc.proxy.ping(NODE).result(WAIT)["bus"], 1)
        self.assertEqual(obc.proxy.switch_bus(None), 0)
        self.assertEqual(obc.proxy.switch_bus(0), 0)  # already active: no event
        with self.assertRaises(ComponentError) as cm:
            obc.proxy.switch_bus("C")
        self.assertEqual(cm.exception.code, BAD_REQUEST)
        obc.run(0.1)
        got = [p.value for p in drain(failovers)]
        self.assertEqual(
            got,
            [
                {"old": "A", "new": "B", "reason": "commanded"},
                {"old": "B", "new": "A", "reason": "commanded"},
            ],
        )

    def test_bus_state_attributes(self):
        obc = Obc()
        states = obc.proxy.subscribe("bus_a_state")
        self.assertEqual(obc.proxy.bus_a_state, "silent")
        obc.proxy.ping(NODE).result(WAIT)
        obc.run(0.6)
        self.assertEqual(obc.proxy.bus_a_state, "ok")
        obc.run(3.0)  # nothing received for more than four heartbeat periods
        self.assertEqual(obc.proxy.bus_a_state, "silent")
        self.assertEqual([p.value for p in drain(states)], ["ok", "silent"])
        status = obc.proxy.bus_status
        self.assertEqual([s["bus"] for s in status], [0, 1])
        self.assertTrue(status[0]["active"])
        self.assertEqual(obc.proxy.rx_frames, status[0]["rx_frames"] + status[1]["rx_frames"])
        self.assertEqual(obc.proxy.tx_errors, 0)
        self.assertEqual(obc.proxy.tx_frames, obc.ctrl.counters["tx"])


class TestWithoutInteractionLayer(unittest.TestCase):
    def test_master_is_a_bus_node_and_keeps_events(self):
        c = Controller(heartbeat_period=0.5, timeout=0.2, retries=1)
        c.add_node(NODE, definition())
        m = SpaceCanMaster(c, keep_events=3)
        r = Responder(NODE, definition())
        net = SimNetwork().attach(m, r)
        net.run(0.1)
        req = c.ping(NODE, net.now)
        net.run_until(lambda: req.done, WAIT)
        self.assertEqual(record(req)["status"], "completed")
        kinds = [e.kind for e in m.take_events()]
        # (1,1), (17,2), (1,7), done: the oldest went
        self.assertEqual(kinds, [ev.PING_REPORT, ev.VERIFICATION, ev.REQUEST_DONE])
        self.assertEqual(m.dropped_events, 1)
        self.assertEqual(m.take_events(), [])
        self.assertEqual(m.switch_bus(1), 1)
        self.assertEqual(m.active_bus, 1)  # unbound: the attribute is set, nothing published


if __name__ == "__main__":
    unittest.main()
