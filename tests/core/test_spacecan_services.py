"""SpaceCAN controller and responder over the simulated bus: services, verification, timeouts."""

import unittest

from obsw.spacecan import events as ev
from obsw.spacecan import packets as pk
from obsw.spacecan.controller import COMPLETED, FAILED, REJECTED, TIMEOUT, Controller
from obsw.spacecan.ids import ID_HEARTBEAT
from obsw.spacecan.nodedef import NodeDefinition
from obsw.spacecan.responder import Responder
from obsw.spacecan.sim import SimNetwork

NODE = {
    "parameters": [
        {"parameter_id": 1, "parameter_name": "mode", "encoding": "u8", "value": 3},
        {"parameter_id": 2, "parameter_name": "volt", "encoding": "f32", "value": 7.5},
        {"parameter_id": 3, "parameter_name": "count", "encoding": "u32", "value": 0x12345678},
        {"parameter_id": 4, "parameter_name": "temp", "encoding": "i16", "value": -20},
    ],
    "housekeeping_reports": [
        {"report_id": 1, "interval": 1, "enabled": False, "parameter_ids": [1, 4]},
        {"report_id": 2, "interval": 0.25, "enabled": False, "parameter_ids": [2]},
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


def h(s):
    return bytes.fromhex(s)


def setup(**kw):
    c = Controller(timeout=0.2, retries=1, **kw)
    c.add_node(1, NodeDefinition.from_dict(NODE))
    r = Responder(1, NodeDefinition.from_dict(NODE))
    net = SimNetwork(trace=True).attach(c, r)
    return c, r, net


def run(net, req, timeout=5.0):
    net.run_until(lambda: req.done, timeout)
    return req


def frames(net, skip_heartbeat=True):
    out = [(t[2], t[3].hex()) for t in net.trace if not (skip_heartbeat and t[2] == ID_HEARTBEAT)]
    net.trace[:] = []
    return out


def kinds(node):
    return [e.kind for e in node.take_events()]


class TestServices(unittest.TestCase):
    def test_ping_frames_as_traced(self):
        c, r, net = setup()
        req = run(net, c.ping(1, net.now))
        self.assertEqual(req.status, COMPLETED)
        self.assertIs(req.result, True)
        self.assertEqual(req.reports, [1, 7])
        self.assertEqual(
            frames(net),
            [
                (0x281, "00001101"),
                (0x301, "000001011101"),
                (0x301, "00001102"),
                (0x301, "000001071101"),
            ],
        )
        self.assertIn(ev.PING_REPORT, kinds(c))

    def test_parameters_frames_as_traced(self):
        c, r, net = setup()
        req = run(net, c.request_parameters(1, [1, 2, 3, 4], net.now))
        self.assertEqual(req.result, {1: 3, 2: 7.5, 3: 0x12345678, 4: -20})
        self.assertEqual(
            frames(net),
            [
                (0x281, "0100140104010203"),
                (0x281, "010104"),
                (0x301, "000001011401"),
                (0x301, "0200140204010302"),
                (0x301, "020140f000000312"),
                (0x301, "020234567804ffec"),
                (0x301, "000001071401"),
            ],
        )
        evs = [e for e in c.take_events() if e.kind == ev.PARAMETER_REPORT]
        self.assertEqual(evs[0].values[4], -20)

    def test_unknown_parameter_rejected(self):
        c, r, net = setup()
        req = run(net, c.request_parameters(1, [9], net.now))
        self.assertEqual(req.status, REJECTED)
        self.assertEqual(frames(net), [(0x281, "000014010109"), (0x301, "000001021401")])

    def test_one_shot_housekeeping(self):
        c, r, net = setup()
        req = run(net, c.request_housekeeping(1, [1], net.now))
        self.assertEqual(req.status, COMPLETED)
        self.assertEqual(req.result, {1: {1: 3, 4: -20}})
        self.assertIn((0x301, "000003190103ffec"), frames(net))

    def test_periodic_housekeeping(self):
        c, r, net = setup()
        run(net, c.enable_housekeeping(1, [2], net.now))
        c.take_events()
        r.set_value("volt", 1.25)
        net.run(1.01)
        reports = [e for e in c.take_events() if e.kind == ev.HOUSEKEEPING_REPORT]
        self.assertEqual(len(reports), 4)
        self.assertEqual(reports[0].values, {2: 1.25})
        self.assertEqual(reports[0].report_id, 2)
        run(net, c.disable_housekeeping(1, [2], net.now))
        c.take_events()
        net.run(1.0)
        self.assertEqual([e for e in c.take_events() if e.kind == ev.HOUSEKEEPING_REPORT], [])

    def test_housekeeping_bad_ids_rejected(self):
        c, r, net = setup()
        for ids in ([], [7]):
            req = run(net, c.enable_housekeeping(1, ids, net.now))
            self.assertEqual(req.status, REJECTED)

    def test_function_call(self):
        c, r, net = setup()
        calls = []
        r.on_function = lambda fid, args: calls.append((fid, args))
        req = run(net, c.call_function(1, 1, net.now, {1: 1}))
        self.assertEqual(req.status, COMPLETED)
        self.assertEqual(calls, [(1, {1: 1})])
        self.assertEqual(frames(net)[0], (0x281, "0000080101010101"))
        req = run(net, c.call_function(1, 2, net.now))
        self.assertEqual(req.status, COMPLETED)
        self.assertEqual(frames(net)[0], (0x281, "0000080102"))
        self.assertEqual(calls[-1], (2, {}))

    def test_function_failure_and_rejection(self):
        c, r, net = setup()
        r.on_function = lambda fid, args: False
        self.assertEqual(run(net, c.call_function(1, 2, net.now)).status, FAILED)

        def boom(fid, args):
            raise RuntimeError("line stuck")

        r.on_function = boom
        req = run(net, c.call_function(1, 2, net.now))
        self.assertEqual(req.status, FAILED)
        self.assertEqual(req.reports, [1, 8])
        self.assertEqual(run(net, c.call_function(1, 9, net.now)).status, REJECTED)
        # an argument missing
        req = run(net, c.request(1, 8, 1, h("01"), net.now))
        self.assertEqual(req.status, REJECTED)

    def test_set_parameters_extension(self):
        c, r, net = setup()
        req = run(net, c.set_parameters(1, {1: 9, 4: -1}, net.now))
        self.assertEqual(req.status, COMPLETED)
        self.assertEqual((r.get_value(1), r.get_value("temp")), (9, -1))
        r.on_parameters_set = lambda values: False
        self.assertEqual(run(net, c.set_parameters(1, {1: 10}, net.now)).status, FAILED)
        self.assertEqual(r.get_value(1), 9)

    def test_unsupported_services_answered(self):
        c, r, net = setup()
        for service, subtype in ((99, 1), (17, 5), (1, 1), (3, 25)):
            req = run(net, c.request(1, service, subtype, b"", net.now))
            self.assertEqual(req.status, REJECTED)
            self.assertEqual(frames(net)[-1], (0x301, "00000102%02x%02x" % (service, subtype)))
        self.assertEqual(r.counters["rejected"], 4)
        self.assertIn(ev.REQUEST_REJECTED, kinds(r))

    def test_verification_reports_surfaced(self):
        c, r, net = setup()
        req = run(net, c.ping(1, net.now))
        v = [e for e in c.take_events() if e.kind == ev.VERIFICATION]
        self.assertEqual([e.subtype for e in v], [1, 7])
        self.assertIs(v[0].request, req)
        self.assertEqual((v[0].service, v[0].req_subtype, v[0].node), (17, 1, 1))
        # an unsolicited report still surfaces, matched to no request
        net.inject(0, 0x301, h("000001071101"))
        v = [e for e in c.take_events() if e.kind == ev.VERIFICATION]
        self.assertIsNone(v[0].request)
        self.assertEqual(c.counters["unmatched"], 1)

    def test_silent_node_times_out(self):
        c = Controller(timeout=0.2, retries=2)
        c.add_node(5)
        net = SimNetwork().attach(c)
        req = c.ping(5, net.now)
        self.assertFalse(net.run_until(lambda: req.done, 0.5))
        self.assertTrue(net.run_until(lambda: req.done, 5.0))
        self.assertEqual(req.status, TIMEOUT)
        self.assertEqual(req.attempts, 3)
        self.assertIn("node 5", req.error)

    def test_accepted_but_not_completed(self):
        c, r, net = setup()
        net.drop(
            count=2, can_id=0x301
        )  # keep (1,1), lose (17,2)? no: lose first two: (1,1),(17,2)
        net.drop(count=1, can_id=0x301)
        req = c.ping(1, net.now)
        run(net, req)
        self.assertEqual(req.status, COMPLETED)  # the re-sent ping got all three answers
        self.assertEqual(req.attempts, 2)

        class AcceptOnly:
            def __init__(self):
                self.out = []

            def receive(self, bus, can_id, data, now):
                if can_id == 0x282:
                    self.out.append((bus, 0x302, h("000001011101")))

            def poll(self, now):
                pass

            def next_deadline(self):
                return None

            def take_frames(self):
                o, self.out = self.out, []
                return o

        c.add_node(2)
        net.attach(AcceptOnly())
        req = run(net, c.ping(2, net.now))
        self.assertEqual(req.status, TIMEOUT)
        self.assertEqual(req.attempts, 1)  # accepted commands are never sent twice
        self.assertIn("accepted", req.error)

    def test_requests_in_line_per_service(self):
        c, r, net = setup()
        a = c.ping(1, net.now)
        b = c.ping(1, net.now)
        p = c.request_parameters(1, [1], net.now)
        self.assertEqual(len(c.pending()), 3)
        net.run_until(lambda: a.done and b.done and p.done, 2.0)
        self.assertEqual((a.status, b.status, p.status), (COMPLETED, COMPLETED, COMPLETED))
        self.assertEqual(p.result, {1: 3})
        self.assertEqual(c.pending(), [])

    def test_cancel(self):
        c, r, net = setup()
        a = c.ping(1, net.now)
        b = c.ping(1, net.now)
        c.cancel(b, net.now)
        run(net, a)
        self.assertEqual(b.status, "cancelled")
        self.assertEqual(sum(1 for f in frames(net) if f[0] == 0x281), 1)

    def test_stray_fragment_never_blocks(self):
        c, r, net = setup()
        net.inject(0, 0x281, h("0201dead"))
        req = run(net, c.ping(1, net.now))
        self.assertEqual(req.status, COMPLETED)
        self.assertEqual(req.attempts, 1)
        self.assertEqual(r.reassembler.counters["stray"], 1)

    def test_corrupted_fragment_recovered_by_retry(self):
        c, r, net = setup()
        net.corrupt(count=1, can_id=0x281, byte=1, mask=0x02)  # index 0 -> 2: not a start
        req = run(net, c.request_parameters(1, [1, 2, 3, 4], net.now))
        self.assertEqual(req.status, COMPLETED)
        self.assertEqual(req.attempts, 2)

    def test_time_frames(self):
        c, r, net = setup()
        c.send_scet(0x11223344, 0xAABBCC)
        c.send_utc(0x1122, 0xAABBCCDD, 0xEEFF)
        c.send_sync()
        net.pump()
        self.assertEqual(
            frames(net), [(0x180, "aabbcc11223344"), (0x200, "eeffaabbccdd1122"), (0x080, "")]
        )
        evs = r.take_events()
        self.assertEqual([e.kind for e in evs], [ev.SCET, ev.UTC, ev.SYNC])
        self.assertEqual(r.scet.coarse_time, 0x11223344)
        self.assertEqual(r.utc.day, 0x1122)

    def test_bad_time_frames_counted(self):
        c, r, net = setup()
        net.inject(0, 0x180, h("aabbcc112233"))
        net.inject(0, 0x700, h("01"))
        self.assertEqual(r.counters["bad_frames"], 2)
        self.assertEqual(kinds(r), [ev.FRAME_ERROR, ev.FRAME_ERROR])
        self.assertIsNone(r.scet)

    def test_periodic_sync(self):
        c, r, net = setup(sync_period=0.5)
        net.run(1.01)
        self.assertEqual(sum(1 for e in r.take_events() if e.kind == ev.SYNC), 2)

    def test_decode_errors_reported(self):
        c, r, net = setup()
        net.inject(0, 0x301, h("0000140201ff"))  # (20,2) with id 255: unknown to the controller
        net.inject(0, 0x303, h("00001402010103"))  # node 3: no definition
        evs = [e for e in c.take_events() if e.kind == ev.DECODE_ERROR]
        self.assertEqual(len(evs), 2)
        self.assertIn("255", evs[0].error)

    def test_raw_mode(self):
        c = Controller()
        c.add_node(1)
        r = Responder(1, NodeDefinition.from_dict(NODE), use_packets=False)
        got = []
        r.on_raw = lambda data, bus: got.append((data, bus))
        net = SimNetwork(trace=True).attach(c, r)
        c.send_raw(1, h("0102030405060708"))
        net.pump()
        self.assertEqual(got, [(h("0102030405060708"), 0)])
        r.send_raw(h("aa"))
        net.pump()
        self.assertEqual(frames(net)[-1], (0x301, "aa"))

    def test_request_argument_checks(self):
        c, r, net = setup()
        with self.assertRaises(ValueError):
            c.ping(0, net.now)
        with self.assertRaises(ValueError):
            c.request(1, 17, 1, bytes(1535), net.now)
        with self.assertRaises(ValueError):
            c.set_parameters(1, {9: 1}, net.now)
        c.add_node(2)
        with self.assertRaises(ValueError):
            c.set_parameters(2, {1: 1}, net.now)

    def test_config_from_spacecan_json(self):
        r = Responder.from_config(
            {
                "interface": "socketcan",
                "channel_a": "can0",
                "channel_b": "can1",
                "node_id": 7,
                "max_miss_heartbeat": 2,
            },
            NodeDefinition.from_dict(NODE),
        )
        self.assertEqual((r.node_id, r.monitor.max_miss), (7, 2))
        c = Controller.from_config({"heartbeat_period": 0.25, "sync_period": 5})
        self.assertEqual((c.heartbeat_period, c.sync_period), (0.25, 5))
        with self.assertRaises(ValueError):
            Responder.from_config(
                {"node_id": 7, "max_bus_switch": "x"}, NodeDefinition.from_dict(NODE)
            )
        self.assertIsNotNone(pk.SERVICE_TEST)
