"""Equipment components generated from SpaceCAN node definitions: the interface and its ids,
operations as service 8 functions through the master, attributes fed by housekeeping, errors
and bus failover, and the equipment in another IL node than the master."""

import unittest

from obsw.il.clock import SimClock
from obsw.il.errors import ComponentError, UnavailableError
from obsw.il.interface import DATA, EVENT, check_unique_ids
from obsw.il.loopback import connect, resolver_for
from obsw.il.node import Node
from obsw.spacecan.equipment import (
    EVENT_BASE,
    FUNCTION_BASE,
    INTERFACE_BASE,
    PARAMETER_BASE,
    SERVICE_BASE,
    Equipment,
    EquipmentError,
    equipment_interface,
    member_name,
)
from obsw.spacecan.master import MASTER
from obsw.spacecan.nodedef import NodeDefinition
from spacecan_obc_sim import CPDU, NODE, WAIT, Obc, definition, drain, manual


def _node(parameters, functions):
    return NodeDefinition.from_dict(
        {"parameters": parameters, "housekeeping_reports": [], "functions": functions}
    )


class TestInterface(unittest.TestCase):
    def test_generated_from_definition(self):
        itf = equipment_interface("CpduN", NODE, definition())
        self.assertEqual((itf.name, itf.id), ("CpduN", INTERFACE_BASE + NODE))
        a = itf.member("state_bits")
        self.assertEqual((a.id, a.kind, a.type), (PARAMETER_BASE + 1, DATA, "u16"))
        op = itf.member("set_state_bits")
        self.assertEqual(
            (op.id, op.params, op.asynchronous), (FUNCTION_BASE + 1, ("state_bits",), True)
        )
        self.assertEqual(itf.member("pulse").params, ("line", "ms"))
        self.assertEqual(itf.member("self_test").params, ())
        self.assertEqual(itf.member("request_parameters").id, SERVICE_BASE)
        self.assertEqual(itf.member("ping").params, ())
        ev = itf.member("housekeeping")
        self.assertEqual((ev.member, ev.id), (EVENT, EVENT_BASE))
        self.assertEqual(
            [m.name for m in itf.attributes], ["state_bits", "board_temp", "supply_mv"]
        )

    def test_ids_are_deterministic_and_unique(self):
        one = equipment_interface("CpduN", NODE, definition())
        two = equipment_interface("CpduN", NODE, NodeDefinition.from_json(definition().to_json()))
        self.assertEqual(
            sorted((m.name, m.id) for m in one.members.values()),
            sorted((m.name, m.id) for m in two.members.values()),
        )
        ids = [m.id for m in one.members.values()]
        self.assertEqual(len(ids), len(set(ids)))
        other = equipment_interface("CpduR", 6, definition())
        check_unique_ids([MASTER, one, other])
        with self.assertRaises(ValueError):
            check_unique_ids([MASTER, one, equipment_interface("Again", NODE, definition())])
        with self.assertRaises(ValueError):
            check_unique_ids([one, equipment_interface("CpduN", 7, definition())])
        fixed = equipment_interface("Fixed", NODE, definition(), interface_id=0x7000)
        self.assertEqual(fixed.id, 0x7000)

    def test_names_and_clashes(self):
        self.assertEqual(member_name("board temp.C", "x"), "board_temp_C")
        self.assertEqual(member_name("", "parameter_4"), "parameter_4")
        itf = equipment_interface(
            "Odd",
            3,
            _node(
                [
                    {"parameter_id": 4, "encoding": "u8"},
                    {"parameter_id": 5, "parameter_name": "ping", "encoding": "u8"},
                ],
                [{"function_id": 1}],
            ),
        )
        self.assertEqual(itf.member("parameter_4").id, PARAMETER_BASE + 4)
        self.assertEqual(itf.member("function_1").id, FUNCTION_BASE + 1)
        self.assertEqual(itf.member("ping").member, 1)  # the parameter; generic ping left out
        with self.assertRaises(EquipmentError):
            equipment_interface(
                "Bad",
                3,
                _node(
                    [{"parameter_id": 1, "parameter_name": "mode", "encoding": "u8"}],
                    [{"function_id": 1, "function_name": "mode"}],
                ),
            )
        with self.assertRaises(ValueError):
            equipment_interface("Bad", 0, definition())  # not a responder node id

    def test_from_json(self):
        import json

        eq = Equipment.from_json("CpduN", NODE, json.dumps(CPDU))
        self.assertEqual(eq.interface.member("set_state_bits").id, FUNCTION_BASE + 1)
        self.assertIsNone(eq.values.state_bits)  # not reported yet


class TestOperations(unittest.TestCase):
    def test_set_state_bits_goes_out_as_service_8_and_completes(self):
        obc = Obc()
        eq, cpdu = obc.equipment()
        updates = []
        p = cpdu.set_state_bits(0x0A5, on_status=lambda p, s, v: updates.append(v))
        rec = p.result(WAIT)
        self.assertEqual((rec["status"], rec["service"], rec["subtype"]), ("completed", 8, 1))
        self.assertEqual(obc.calls, [(1, {1: 0x0A5})])
        frames = obc.requests_to(NODE)
        self.assertEqual([f[0] for f in frames], [0, 0, 0])  # all on bus A
        packet = frames[0][1][2:] + frames[1][1][2:]  # after each 2-byte fragment header
        self.assertEqual(packet, bytes((8, 1, 1, 1, 1, 0x00, 0xA5)))  # (8,1) f=1 n=1 a=1 u16
        # then the node's parameters read back, so the function's effect reads at once
        self.assertEqual(frames[2][1][2:], bytes((20, 1, 3, 1, 2, 3)))  # (20,1) of ids 1..3
        self.assertEqual(cpdu.state_bits, 0x0A5)
        self.assertIn("accepted", [u["status"] for u in updates if isinstance(u, dict)])
        self.assertEqual(cpdu.pulse(2, 100).result(WAIT)["status"], "completed")
        self.assertEqual(cpdu.pulse(line=3, ms=5).result(WAIT)["status"], "completed")
        self.assertEqual(obc.calls[1:], [(2, {1: 2, 2: 100}), (2, {1: 3, 2: 5})])
        self.assertEqual(eq.check(), 0)

    def test_bad_argument_refused_before_the_bus(self):
        obc = Obc()
        eq, cpdu = obc.equipment()
        before = len(obc.bus_frames())
        with self.assertRaises(ComponentError) as cm:
            cpdu.set_state_bits(70000).result(WAIT)
        self.assertEqual(cm.exception.code, "BAD_REQUEST")
        self.assertEqual(cm.exception.data["argument"], "state_bits")
        with self.assertRaises(ComponentError):
            cpdu.request_parameters(["no_such"]).result(WAIT)
        with self.assertRaises(ComponentError):
            cpdu.set_parameters({"state_bits": "on"}).result(WAIT)
        self.assertEqual(len(obc.bus_frames()), before)

    def test_parameters_requested_and_set(self):
        obc = Obc()
        eq, cpdu = obc.equipment()
        self.assertIsNone(cpdu.state_bits)
        got = cpdu.request_parameters(None).result(WAIT)
        self.assertEqual(got, {"state_bits": 0, "board_temp": 24.5, "supply_mv": 5020})
        self.assertEqual(cpdu.supply_mv, 5020)
        self.assertEqual(cpdu.request_parameters("board_temp").result(WAIT), {"board_temp": 24.5})
        values = cpdu.subscribe("state_bits")
        rec = cpdu.set_parameters({"state_bits": 0x00F}).result(WAIT)
        self.assertEqual(rec["reports"], [1, 7])
        self.assertEqual(obc.resp.get_value(1), 0x00F)
        self.assertEqual(cpdu.state_bits, 0x00F)
        self.assertEqual([p.value for p in drain(values)], [0x00F])
        self.assertIs(cpdu.ping().result(WAIT)["result"], True)

    def test_housekeeping_feeds_attributes_and_publications(self):
        obc = Obc()
        eq, cpdu = obc.equipment()
        values = cpdu.subscribe("state_bits", length=16)
        reports = cpdu.subscribe("housekeeping", length=16)
        cpdu.enable_housekeeping([1]).result(WAIT)
        obc.run(2.5)
        self.assertEqual(cpdu.state_bits, 0)
        self.assertEqual(cpdu.board_temp, 24.5)
        self.assertIsNone(cpdu.supply_mv)  # not in report 1
        cpdu.set_state_bits(0x0C3).result(WAIT)
        obc.run(1.5)
        self.assertEqual(cpdu.state_bits, 0x0C3)
        got = [p.value for p in drain(values)]
        self.assertEqual(got[0], 0)
        self.assertEqual(got[-1], 0x0C3)
        hk = drain(reports)
        self.assertEqual(len(hk), eq.reports)
        self.assertTrue(len(hk) >= 3)
        self.assertEqual(hk[0].name, "CpduN.housekeeping")
        self.assertEqual(
            hk[-1].value, {"report_id": 1, "values": {"state_bits": 0x0C3, "board_temp": 24.5}}
        )
        cpdu.request_housekeeping(2).result(WAIT)
        obc.run(0.1)
        self.assertEqual(cpdu.supply_mv, 5020)
        cpdu.disable_housekeeping([1]).result(WAIT)
        obc.run(3.0)
        self.assertEqual(len(drain(reports)), 1)  # the one-shot report 2 only

    def test_other_nodes_reports_are_not_ours(self):
        obc = Obc()
        eq5, cpdu = obc.equipment()
        eq6, other = obc.equipment("CpduR", 6)
        obc.proxy.enable_housekeeping(NODE, [1]).result(WAIT)
        obc.run(1.5)
        self.assertEqual(cpdu.board_temp, 24.5)
        self.assertIsNone(other.board_temp)
        self.assertEqual((eq5.reports, eq6.reports), (1, 0))


class TestFaults(unittest.TestCase):
    def test_silent_node_gives_timeout_error(self):
        obc = Obc(policy=manual())
        eq, ghost = obc.equipment("Ghost", 6)  # declared, but no node 6 on the bus
        unresponsive = ghost.subscribe("unresponsive")
        with self.assertRaises(ComponentError) as cm:
            ghost.set_state_bits(1).result(WAIT)
        self.assertEqual(cm.exception.code, "TIMEOUT")
        self.assertEqual(cm.exception.data["attempts"], 3)
        self.assertEqual(cm.exception.target, "Ghost.set_state_bits")
        self.assertTrue(obc.net.now < 1.0)  # the controller's 3 x 0.2 s, not the caller's 30 s
        obc.run(0.1)
        self.assertEqual(drain(unresponsive)[0].value["service"], 8)

    def test_failed_and_rejected_functions(self):
        obc = Obc()
        eq, cpdu = obc.equipment()
        failed = cpdu.subscribe("command_failed")
        with self.assertRaises(ComponentError) as cm:
            cpdu.self_test().result(WAIT)
        self.assertEqual(cm.exception.code, "FAILED")
        obc.run(0.1)
        self.assertEqual(drain(failed)[0].value, {"service": 8, "subtype": 1, "report": 8})

    def test_bus_failure_mid_command_completes_on_b(self):
        obc = Obc(retries=3)
        eq, cpdu = obc.equipment()
        master_active = obc.proxy.subscribe("active_bus")
        p = cpdu.set_state_bits(0x111)
        obc.node.poll()  # the equipment has run: it called the master ...
        obc.node.poll()  # ... which has sent the request on bus A
        self.assertEqual(obc.master.pending_requests, 1)
        obc.net.kill(0)
        rec = p.result(WAIT)
        self.assertEqual((rec["status"], rec["bus"]), ("completed", 1))
        self.assertEqual(obc.calls, [(1, {1: 0x111})])
        obc.run(0.1)
        self.assertEqual(drain(master_active)[-1].value, 1)
        self.assertEqual(
            cpdu.request_parameters(["state_bits"]).result(WAIT), {"state_bits": 0x111}
        )


class TestAcrossNodes(unittest.TestCase):
    def setUp(self):
        self.obc = Obc()
        self.eq_node = self.obc.clock.watch(Node("equipment", clock=self.obc.clock))
        self.eq_node.registry.resolver = resolver_for(
            self.eq_node, lambda: [self.obc.node], codec=True
        )

    def test_equipment_in_another_node_through_cbor(self):
        eq, cpdu = self.obc.equipment(node=self.eq_node)
        values = cpdu.subscribe("state_bits", length=16)
        rec = cpdu.set_state_bits(0x2AA).result(WAIT)
        self.assertEqual((rec["status"], rec["bus"]), ("completed", 0))
        cpdu.enable_housekeeping([1]).result(WAIT)
        self.obc.run(1.5)
        self.assertEqual(cpdu.state_bits, 0x2AA)
        self.assertEqual(drain(values)[-1].value, 0x2AA)
        with self.assertRaises(ComponentError) as cm:
            cpdu.self_test().result(WAIT)
        self.assertEqual(cm.exception.code, "FAILED")

    def test_lost_master_fails_the_job(self):
        clock = SimClock()
        master_node = Node("far-master", clock=clock)
        user = Node("user", clock=clock)
        links = []

        def resolve(name):
            if name != MASTER.name or links:
                return None
            a, b = connect(user, master_node, codec=True)
            links.append(a)
            return a

        class Silent:  # accepts requests and never finishes them
            def il_bind(self, provider):
                pass

            def __getattr__(self, name):
                return lambda job, *args: None

        master_node.provide(MASTER, Silent())
        user.registry.resolver = resolve
        eq = Equipment("CpduN", NODE, definition(), timeout=1.0)
        eq.provide(user)
        cpdu = user.proxy(eq.interface, timeout=1.0)
        p = cpdu.set_state_bits(1)
        user.poll()
        master_node.poll()
        self.assertEqual(eq.check(), 1)
        links[0].cut()
        self.assertEqual(eq.check(), 0)
        with self.assertRaises(UnavailableError):
            p.result(1.0)


if __name__ == "__main__":
    unittest.main()
