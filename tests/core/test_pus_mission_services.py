"""Mission-specific services (types 128..255) declared in the database, served on a component."""

import json
import unittest

from obsw.il.clock import SimClock
from obsw.il.errors import ComponentError
from obsw.il.interface import Event, Interface, Operation
from obsw.il.node import Node
from obsw.pluto.il_system import IlSystem
from obsw.pluto.interp import Procedure, load
from obsw.pluto.lexer import PlutoError
from obsw.pus.messages import FAILURE_ILLEGAL_SUBTYPE
from obsw.pus.sdb import Sdb, SdbError
from obsw.pus.services.mission import MissionArgumentError, MissionService, MissionServiceUser
from obsw.pus.services.s01_verification import (
    FAILURE_COMPONENT,
    FAILURE_EXECUTION,
    FAILURE_ILLEGAL_APP_DATA,
    FAILURE_OUT_OF_RANGE,
    FAILURE_UNAVAILABLE,
)
from pus_loop import APID, SDB, Loop

CAMERA = Interface(
    "Camera",
    0x70,
    [
        Operation("take_picture", 1, ("exposure", "gain")),
        Operation("calibrate", 2, (), asynchronous=True),
        Operation("broken", 3, ()),
        Event("overheated", 4, fields=("temperature",)),
    ],
)

SERVICE = {
    "type": 140,
    "name": "payload",
    "component": "Camera",
    "requests": [
        {
            "subtype": 1,
            "name": "take_picture",
            "operation": "take_picture",
            "report": 2,
            "arguments": [
                {"name": "exposure", "type": "uint16", "unit": "ms", "range": [1, 1000]},
                {"name": "gain", "type": "int8", "range": [-10, 10]},
            ],
        },
        {"subtype": 3, "name": "calibrate", "operation": "calibrate"},
        {"subtype": 5, "name": "broken", "operation": "broken", "report": 2},
    ],
    "reports": [
        {
            "subtype": 2,
            "name": "picture_report",
            "fields": [
                {"name": "picture", "type": "uint32"},
                {"name": "mean", "type": "float32", "unit": "DN"},
            ],
        },
        {
            "subtype": 4,
            "name": "overheat_report",
            "event": "overheated",
            "fields": [{"name": "temperature", "type": "float32", "unit": "degC"}],
        },
    ],
}


class Camera:
    def __init__(self):
        self.calls = []
        self.il = None

    def il_bind(self, provider):
        self.il = provider

    def take_picture(self, exposure, gain):
        if exposure == 999:
            raise ComponentError("SHUTTER", "shutter stuck")
        self.calls.append(("take_picture", exposure, gain))
        return {"picture": len(self.calls), "mean": exposure / 2.0}

    def calibrate(self, job):
        self.calls.append(("calibrate",))
        job.update(1)
        job.succeed(None)

    def broken(self):
        return "not a picture report"


def database(services=None):
    doc = json.loads(SDB)
    doc["services"] = [SERVICE] if services is None else services
    return Sdb(doc)


def make(with_node=True):
    db = database()
    node = Node("obc", SimClock()) if with_node else None
    camera = Camera()
    if node is not None:
        node.provide(CAMERA, camera)
    loop = Loop()
    provider = loop.app.register(MissionService(db.service("payload"), node, timeout=1.0))
    user = loop.ground.register(MissionServiceUser(db.service(140)))
    return loop, provider, user, camera, node


def failure(tx):
    return (tx.failure["stage"], tx.failure["code"], tx.failure["data"]) if tx.failure else None


class TestDeclaration(unittest.TestCase):
    def test_parsed_with_types_and_signatures(self):
        db = database()
        s = db.service("payload")
        self.assertIs(db.service(140), s)
        self.assertEqual(sorted(s.requests), [1, 3, 5])
        self.assertEqual(sorted(s.reports), [2, 4])
        self.assertEqual(s.request("take_picture").message_type, (140, 1))
        self.assertEqual(s.message(2).name, "picture_report")
        self.assertEqual(s.operation(s.request(1)), "Camera.take_picture")
        op = db.operations["Camera.take_picture"]  # the activity PLUTO checks against
        self.assertEqual(op.signature, [("exposure", "uint16", "ms"), ("gain", "int8", None)])

    def test_service_types_below_128_are_the_standards(self):
        for t in (17, 127, 256, "140"):
            bad = dict(SERVICE, type=t)
            with self.assertRaises(SdbError):
                database([bad])

    def test_subtypes_and_names_once(self):
        reports = SERVICE["reports"] + [{"subtype": 1, "name": "again", "fields": []}]
        with self.assertRaises(SdbError):
            database([dict(SERVICE, reports=reports)])
        with self.assertRaises(SdbError):
            database([SERVICE, dict(SERVICE, name="other")])  # type 140 twice
        with self.assertRaises(SdbError):
            database([SERVICE, dict(SERVICE, type=141)])  # name twice

    def test_bad_types_ranges_and_report_references(self):
        arg = {"name": "x", "type": "uint7"}
        req = {"subtype": 1, "name": "r", "operation": "op", "arguments": [arg]}
        with self.assertRaises(SdbError):
            database([dict(SERVICE, requests=[req], reports=[])])
        arg = {"name": "x", "type": "uint8", "range": [0, 300]}
        req["arguments"] = [arg]
        with self.assertRaises(SdbError):
            database([dict(SERVICE, requests=[req], reports=[])])
        req = {"subtype": 1, "name": "r", "operation": "op", "report": 9}
        with self.assertRaises(SdbError):
            database([dict(SERVICE, requests=[req], reports=[])])


class TestProvider(unittest.TestCase):
    def test_request_calls_the_operation_and_reports_its_reply(self):
        loop, provider, user, camera, _ = make()
        tx = loop.run_async(lambda: user.send(APID, "take_picture", {"exposure": 20, "gain": -2}))
        self.assertTrue(tx.ok)
        self.assertEqual(camera.calls, [("take_picture", 20, -2)])
        self.assertEqual(
            tx.reply,
            {
                "service": "payload",
                "report": "picture_report",
                "fields": {"picture": 1, "mean": 10.0},
            },
        )
        self.assertIn((140, 2), loop.types())
        self.assertEqual(provider.REPORTS, ((140, 2), (140, 4)))

    def test_asynchronous_operation_reports_progress(self):
        loop, _, user, camera, _ = make()
        tx = loop.run_async(lambda: user.send(APID, "calibrate", {}))
        self.assertEqual(
            tx.verification(),
            [
                "acceptance success",
                "start success",
                "progress success step 1",
                "completion success",
            ],
        )

    def test_out_of_range_fails_acceptance_with_the_argument_index(self):
        loop, _, user, camera, _ = make()
        data = user.definition.request(1).layout.pack({"exposure": 20, "gain": 11})
        tx = loop.run(loop.ground.send(APID, 140, 1, data))
        self.assertEqual(failure(tx), (1, FAILURE_OUT_OF_RANGE, b"\x01"))
        data = user.definition.request(1).layout.pack({"exposure": 0, "gain": 0})
        tx = loop.run(loop.ground.send(APID, 140, 1, data))
        self.assertEqual(failure(tx), (1, FAILURE_OUT_OF_RANGE, b"\x00"))
        self.assertEqual(camera.calls, [])

    def test_short_long_and_unknown_requests_fail_acceptance(self):
        loop, _, _, camera, _ = make()
        for data in (b"", b"\x00\x14", b"\x00\x14\x00\x00"):
            tx = loop.run(loop.ground.send(APID, 140, 1, data))
            self.assertEqual(failure(tx)[:2], (1, FAILURE_ILLEGAL_APP_DATA))
        tx = loop.run(loop.ground.send(APID, 140, 2, b""))  # a report's subtype
        self.assertEqual(failure(tx)[:2], (1, FAILURE_ILLEGAL_SUBTYPE))
        self.assertEqual(camera.calls, [])

    def test_component_refusal_and_unfit_reply_fail_completion(self):
        loop, provider, user, _, _ = make()
        tx = loop.run_async(lambda: user.send(APID, 1, {"exposure": 999, "gain": 0}))
        self.assertEqual(failure(tx), (4, FAILURE_COMPONENT, b"\x01"))
        tx = loop.run_async(lambda: user.send(APID, "broken", {}))
        self.assertEqual(failure(tx), (4, FAILURE_EXECUTION, b"\x05"))
        self.assertEqual(provider.unfit_reports, 1)

    def test_random_application_data_gets_a_verdict_never_an_exception(self):
        loop, _, _, camera, _ = make()
        seed = 12345
        for _ in range(200):
            seed = (seed * 1103515245 + 12345) & 0x7FFFFFFF  # the same bytes on both ports
            data = bytes([(seed >> (i % 24)) & 0xFF for i in range(seed % 7)])
            subtype = 1 + seed % 6
            tx = loop.run_async(lambda s=subtype, d=data: loop.ground.send(APID, 140, s, d))
            self.assertTrue(tx.done)
        self.assertEqual(loop.app.counters.get("handler_errors", 0), 0)

    def test_no_interaction_layer_fails_the_start(self):
        loop, _, user, _, _ = make(with_node=False)
        tx = loop.run_async(lambda: user.send(APID, "calibrate", {}))
        self.assertEqual(failure(tx), (2, FAILURE_UNAVAILABLE, b"\x03"))

    def test_component_event_becomes_an_unsolicited_report(self):
        loop, provider, _, camera, node = make()
        camera.il.emit("overheated", {"temperature": 71.5})
        node.poll()
        loop.pump()
        got = loop.unsolicited(140, 4)
        self.assertEqual(
            got,
            [{"service": "payload", "report": "overheat_report", "fields": {"temperature": 71.5}}],
        )
        self.assertEqual(provider.events_reported, 1)


class TestUser(unittest.TestCase):
    def test_arguments_checked_before_sending(self):
        loop, _, user, _, _ = make()
        for given in (
            {"exposure": 20},  # missing
            {"exposure": 20, "gain": 0, "iso": 100},  # unknown
            {"exposure": 20.5, "gain": 0},  # wrong type
            {"exposure": 2000, "gain": 0},  # out of range
            {"exposure": 70000, "gain": 0},  # beyond the type
        ):
            with self.assertRaises(MissionArgumentError):
                user.send(APID, "take_picture", given)
        with self.assertRaises(KeyError):
            user.send(APID, "picture_report", {})
        self.assertEqual(loop.up, [])

    def test_pack_is_the_declared_layout(self):
        _, _, user, _, _ = make()
        self.assertEqual(user.pack("take_picture", {"exposure": 258, "gain": -1}), b"\x01\x02\xff")


def procedure(main):
    return (
        "procedure main initiate and confirm step S main %s end main end step; "
        "end main end procedure" % main
    )


class TestPluto(unittest.TestCase):
    """A request of a mission service is an activity a procedure initiates by its names."""

    def run_procedure(self, src):
        clock = SimClock(1000.0)
        node = Node("obc", clock)
        camera = Camera()
        node.provide(CAMERA, camera)
        system = IlSystem(node, database(), timeout=0.5, activity_timeout=5.0)
        p = Procedure(load(src, system), system, None, poll=0.5)
        p.start(clock.now())
        for _ in range(100):
            node.poll()
            w = p.run(clock.now())
            if p.state != "running" or w is None or w.deadline is None:
                break
            clock.advance(max(0.0, w.deadline - clock.now()))
        return p, camera

    def test_initiate_a_request_by_its_service_and_name(self):
        p, camera = self.run_procedure(procedure(
            "initiate and confirm take picture of payload "
            "with arguments exposure := 20 ms, gain := 1 end with;"
        ))  # fmt: skip
        self.assertEqual(p.outcome, "confirmed")
        self.assertEqual(camera.calls, [("take_picture", 20, 1)])

    def test_the_requests_signature_is_checked_at_load_time(self):
        with self.assertRaises(PlutoError):
            self.run_procedure(procedure(
                "initiate and confirm take picture of payload "
                "with arguments exposure := 20 ms, iso := 1 end with;"
            ))  # fmt: skip


if __name__ == "__main__":
    unittest.main()
