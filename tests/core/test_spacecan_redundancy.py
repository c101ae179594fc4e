"""SpaceCAN redundancy: heartbeat deadlines, both buses received, failover on each side."""

import unittest

from obsw.spacecan import events as ev
from obsw.spacecan.controller import COMPLETED, TIMEOUT, Controller, FailoverPolicy
from obsw.spacecan.ids import BUS_A, BUS_B, ID_HEARTBEAT
from obsw.spacecan.nodedef import NodeDefinition
from obsw.spacecan.redundancy import ConfigError, HeartbeatMonitor
from obsw.spacecan.responder import Responder
from obsw.spacecan.sim import SimNetwork

NODE = {
    "parameters": [{"parameter_id": 1, "parameter_name": "mode", "encoding": "u8", "value": 3}],
    "housekeeping_reports": [
        {"report_id": 1, "interval": 0.5, "enabled": True, "parameter_ids": [1]}
    ],
    "functions": [{"function_id": 1, "function_name": "fire"}],
}


def setup(policy=None, **rkw):
    c = Controller(heartbeat_period=0.5, timeout=0.2, retries=3, policy=policy)
    c.add_node(1, NodeDefinition.from_dict(NODE))
    r = Responder(1, NodeDefinition.from_dict(NODE), heartbeat_period=0.5, **rkw)
    net = SimNetwork(trace=True).attach(c, r)
    return c, r, net


def req_done(req):
    return lambda: req.done


def switches(node):
    return [e for e in node.take_events() if e.kind == ev.BUS_SWITCHED]


class TestHeartbeatMonitor(unittest.TestCase):
    def test_deadline(self):
        m = HeartbeatMonitor(period=0.5, max_miss=3)
        m.start(0.0)
        self.assertEqual(m.next_deadline(), 2.0)
        self.assertIsNone(m.heartbeat(BUS_A, 0.5))
        self.assertEqual(m.next_deadline(), 2.5)
        self.assertIsNone(m.poll(2.49))
        self.assertIsNotNone(m.poll(2.5))
        self.assertEqual(m.active, BUS_B)
        self.assertEqual(m.next_deadline(), 4.5)

    def test_bounded_switching(self):
        m = HeartbeatMonitor(period=0.5, max_miss=1, max_switches=2)
        m.start(0.0)
        self.assertIsNotNone(m.poll(1.0))
        self.assertIsNotNone(m.poll(2.0))
        self.assertIsNone(m.poll(3.0))
        self.assertEqual(m.switch_count, 2)
        self.assertIsNone(m.next_deadline())
        self.assertIsNotNone(m.heartbeat(BUS_B, 3.5))  # B is standby now (A active): follow it
        self.assertEqual(m.active, BUS_B)
        self.assertEqual(m.next_deadline(), 4.5)

    def test_unbounded_switching(self):
        m = HeartbeatMonitor(period=0.1, max_miss=0, max_switches=False)
        m.start(0.0)
        n = 0
        t = 0.0
        while t < 10.0:
            t = m.next_deadline()
            if m.poll(t) is not None:
                n += 1
        self.assertEqual(n, 101)

    def test_follow_standby_only_when_active_is_quiet(self):
        m = HeartbeatMonitor(period=0.5, max_miss=3)
        m.start(0.0)
        m.heartbeat(BUS_A, 1.0)
        self.assertIsNone(m.heartbeat(BUS_B, 1.2))  # A is fine: stay
        self.assertIsNotNone(m.heartbeat(BUS_B, 1.8))  # A quiet for 0.8 s > 1.5 periods
        self.assertEqual(m.active, BUS_B)
        m2 = HeartbeatMonitor(period=0.5, max_miss=3, follow=False)
        m2.start(0.0)
        self.assertIsNone(m2.heartbeat(BUS_B, 1.8))
        self.assertEqual(m2.active, BUS_A)

    def test_heartbeat_off(self):
        m = HeartbeatMonitor(period=0)
        m.start(0.0)
        self.assertIsNone(m.next_deadline())
        self.assertIsNone(m.poll(100.0))

    def test_config_checked(self):
        for kw in (
            {"period": -1},
            {"max_miss": -1},
            {"max_miss": 1.5},
            {"max_switches": -2},
            {"max_switches": True},
            {"max_switches": "x"},
        ):
            with self.assertRaises(ConfigError):
                HeartbeatMonitor(**kw)
        self.assertIsNone(HeartbeatMonitor(max_switches=None).max_switches)
        with self.assertRaises(ConfigError):
            FailoverPolicy(mode="sometimes")
        with self.assertRaises(ConfigError):
            FailoverPolicy(max_timeouts=0)


class TestFailover(unittest.TestCase):
    def test_heartbeats_on_active_bus_only(self):
        c, r, net = setup()
        net.run(2.01)
        hb = [t for t in net.trace if t[2] == ID_HEARTBEAT]
        self.assertEqual([t[0] for t in hb], [0.0, 0.5, 1.0, 1.5, 2.0])
        self.assertEqual(set(t[1] for t in hb), {BUS_A})
        self.assertEqual(r.health[BUS_A].heartbeats, 5)

    def test_bus_a_dies_mid_command(self):
        c, r, net = setup()
        net.run(1.0)
        fired = []
        r.on_function = lambda fid, args: fired.append(fid)
        req = c.call_function(1, 1, net.now)  # frames queued, not yet on the bus
        net.kill(BUS_A)
        self.assertTrue(net.run_until(lambda: req.done, 5.0))
        self.assertEqual(req.status, COMPLETED)
        self.assertEqual(req.bus, BUS_B)
        self.assertEqual(fired, [1])  # nothing lost, nothing done twice
        cs = switches(c)
        self.assertEqual([(e.old, e.new) for e in cs], [(BUS_A, BUS_B)])
        self.assertIn("timeouts", cs[0].reason)
        net.run(1.5)
        self.assertEqual(r.active, BUS_B)
        # and the next request goes straight through on B
        req = c.ping(1, net.now)
        net.run_until(lambda: req.done, 1.0)
        self.assertEqual((req.status, req.attempts), (COMPLETED, 1))

    def test_responder_fails_over_after_configured_misses(self):
        c, r, net = setup(max_miss_heartbeat=3)
        net.run(1.0)
        net.kill(BUS_A)
        net.run(5.0)
        rs = switches(r)
        # last heartbeat at 1.0 on A; deadline 1.0 + 4 * 0.5; the controller keeps sending on A
        self.assertEqual(len(rs), 1)
        self.assertAlmostEqual(rs[0].time, 3.0)
        self.assertEqual(r.active, BUS_B)
        # periodic housekeeping now goes out on B; the controller, hearing nothing on A for
        # four periods, follows the node there, and the responder stays
        evs = c.take_events()
        hk = [e for e in evs if e.kind == ev.HOUSEKEEPING_REPORT]
        self.assertEqual(hk[-1].bus, BUS_B)
        self.assertEqual(c.active, BUS_B)
        cs = [e for e in evs if e.kind == ev.BUS_SWITCHED]
        self.assertIn("nodes heard only on bus B", cs[0].reason)

    def test_commanded_switch_followed_quickly(self):
        c, r, net = setup()
        net.run(1.0)
        c.switch_bus(net.now)
        self.assertEqual(c.active, BUS_B)
        net.run(2.0)
        rs = switches(r)
        self.assertEqual(len(rs), 1)
        self.assertTrue(rs[0].time - 1.0 <= 1.0)  # two periods, not (max_miss + 1)
        self.assertIn("heartbeat on bus B", rs[0].reason)
        cs = switches(c)
        self.assertEqual(cs[0].reason, "command")
        self.assertFalse(c.switch_bus(net.now, BUS_B))

    def test_request_on_standby_bus_answered_there(self):
        c, r, net = setup()
        net.run(0.6)
        c.switch_bus(net.now)
        del net.trace[:]
        req = c.ping(1, net.now)  # the responder still has A active
        net.pump()
        self.assertEqual(r.active, BUS_A)
        self.assertEqual(req.status, COMPLETED)
        self.assertEqual(set(t[1] for t in net.trace if t[2] == 0x301), {BUS_B})

    def test_manual_policy_waits_for_command(self):
        c, r, net = setup(policy=FailoverPolicy(mode="manual"), max_miss_heartbeat=100)
        net.kill(BUS_A)
        req = c.ping(1, net.now)
        net.run_until(lambda: req.done, 5.0)
        self.assertEqual(req.status, TIMEOUT)
        self.assertEqual(c.active, BUS_A)
        c.switch_bus(net.now)
        req = c.ping(1, net.now)
        net.run_until(lambda: req.done, 5.0)
        self.assertEqual(req.status, COMPLETED)

    def test_transmit_errors_switch(self):
        c, r, net = setup(policy=FailoverPolicy(max_tx_errors=2))
        net.kill(BUS_A, tx_errors=True)
        net.run(0.6)  # heartbeats at 0 and 0.5 fail
        self.assertEqual(c.active, BUS_B)
        evs = c.take_events()
        self.assertIn("transmit errors", [e for e in evs if e.kind == ev.BUS_SWITCHED][0].reason)
        self.assertEqual(len([e for e in evs if e.kind == ev.TX_ERROR]), 2)
        self.assertEqual(c.health[BUS_A].tx_errors, 2)

    def test_both_buses_dead_bounded(self):
        c, r, net = setup(policy=FailoverPolicy(max_timeouts=1, max_switches=2))
        net.kill(BUS_A)
        net.kill(BUS_B)
        req = c.ping(1, net.now)
        self.assertTrue(net.run_until(lambda: req.done, 10.0))
        self.assertEqual(req.status, TIMEOUT)
        self.assertEqual(c.counters["switches"], 2)

    def test_bus_status_reports_both(self):
        c, r, net = setup()
        net.run(1.0)
        c.switch_bus(net.now)
        net.run(1.0)
        st = r.bus_status(net.now)
        self.assertEqual([s["bus"] for s in st], [BUS_A, BUS_B])
        self.assertEqual([s["active"] for s in st], [False, True])
        self.assertEqual(st[1]["state"], "ok")
        self.assertEqual(st[0]["heartbeats"], 3)
        cs = c.bus_status(net.now)
        self.assertTrue(cs[1]["active"])
        self.assertEqual(cs[0]["tx_errors"], 0)

    def test_lossy_bus_still_completes(self):
        c, r, net = setup()
        net.set_drop_rate(0.2)
        done = 0
        for _ in range(20):
            req = c.ping(1, net.now)
            net.run_until(req_done(req), 10.0)
            done += req.status == COMPLETED
        self.assertTrue(done >= 15)
        self.assertTrue(net.counters["dropped"] > 0)
