"""ST[08]: functions of the database performed on interaction-layer components."""

import json
import unittest

from obsw import cbor
from obsw.il.clock import SimClock
from obsw.il.errors import ComponentError
from obsw.il.interface import Interface, Operation
from obsw.il.node import Node
from obsw.pus.sdb import Sdb, SdbError
from obsw.pus.services.s01_verification import (
    FAILURE_COMPONENT,
    FAILURE_ILLEGAL_APP_DATA,
    FAILURE_UNAVAILABLE,
    FAILURE_UNKNOWN_ID,
)
from obsw.pus.services.s08_functions import FunctionManagement, FunctionUser, functions
from pus_loop import APID, SDB, Loop

HEATER = Interface(
    "Heater",
    0x60,
    [
        Operation("set_power", 1, ("watts", "zone")),
        Operation("cycle", 2, ("times",), asynchronous=True),
        Operation("off", 3),
    ],
)

FUNCTIONS = [
    {
        "id": 1,
        "name": "Heater.set_power",
        "arguments": [
            {"id": 1, "name": "watts", "type": "float32"},
            {"id": 2, "name": "zone", "type": "uint8", "default": 0},
        ],
    },
    {"id": 2, "name": "Heater.cycle", "arguments": [{"id": 1, "name": "times", "type": "uint8"}]},
    {"id": 3, "name": "Heater.off"},
    {"id": 4, "name": "pus.reset_counters"},
    {"id": 5, "name": "Absent.op"},
]


class Heater:
    def __init__(self):
        self.calls = []

    def set_power(self, watts, zone):
        if watts > 100:
            raise ComponentError("TOO_HOT", "at most 100 W", watts)
        self.calls.append(("set_power", watts, zone))
        return watts

    def cycle(self, job, times):
        self.calls.append(("cycle", times))
        if times == 0:
            job.fail(ComponentError("NOTHING", "zero cycles"))
            return
        job.update(1)
        job.succeed(times)

    def off(self):
        self.calls.append(("off",))


def make():
    doc = json.loads(SDB)
    doc["functions"] = FUNCTIONS
    db = Sdb(doc)
    table = functions(db)
    node = Node("obc", SimClock())
    heater = Heater()
    node.provide(HEATER, heater)
    resets = []
    loop = Loop()
    fm = loop.app.register(
        FunctionManagement(table, node, {4: lambda: resets.append(1)}, timeout=1.0)
    )
    user = loop.ground.register(FunctionUser(table))
    return loop, fm, user, heater, resets


def failure(tx):
    return (tx.failure["stage"], tx.failure["code"], tx.failure["data"]) if tx.failure else None


class TestFunctions(unittest.TestCase):
    def test_perform_with_arguments_by_name_and_default(self):
        loop, fm, user, heater, _ = make()
        tx = loop.run_async(lambda: user.perform(APID, "Heater.set_power", {"watts": 12.5}))
        self.assertTrue(tx.ok)
        tx = loop.run_async(lambda: user.perform(APID, 1, {2: 3, 1: 40.0}))
        self.assertTrue(tx.ok)
        self.assertEqual(heater.calls, [("set_power", 12.5, 0), ("set_power", 40.0, 3)])
        tx = loop.run_async(lambda: user.perform(APID, "Heater.off"))
        self.assertTrue(tx.ok)
        self.assertEqual(heater.calls[-1], ("off",))

    def test_asynchronous_operation_reports_progress(self):
        loop, fm, user, heater, _ = make()
        tx = loop.run_async(lambda: user.perform(APID, "Heater.cycle", {"times": 2}))
        self.assertEqual(
            tx.verification(),
            [
                "acceptance success",
                "start success",
                "progress success step 1",
                "completion success",
            ],
        )
        tx = loop.run_async(lambda: user.perform(APID, "Heater.cycle", {"times": 0}))
        said = cbor.dumps(["NOTHING", "zero cycles", None])
        self.assertEqual(failure(tx), (4, FAILURE_COMPONENT, b"\x00\x02" + said))

    def test_component_errors_fail_the_completion(self):
        loop, fm, user, heater, _ = make()
        tx = loop.run_async(lambda: user.perform(APID, 1, {"watts": 500.0}))
        stage, code, data = failure(tx)
        self.assertEqual((stage, code, data[:2]), (4, FAILURE_COMPONENT, b"\x00\x01"))
        self.assertEqual(cbor.loads(data[2:]), ["TOO_HOT", "at most 100 W", 500.0])
        tx = loop.run_async(lambda: user.perform(APID, "Absent.op"))
        self.assertEqual(failure(tx), (4, FAILURE_UNAVAILABLE, b"\x00\x05"))

    def test_local_function(self):
        loop, fm, user, heater, resets = make()
        tx = loop.run(user.perform(APID, "pus.reset_counters"))
        self.assertTrue(tx.ok)
        self.assertEqual((resets, fm.performed), ([1], 1))

    def test_bad_requests_fail_acceptance(self):
        loop, fm, user, heater, _ = make()
        for data, code in (
            (b"\x00", FAILURE_ILLEGAL_APP_DATA),  # function ID cut short
            (b"\x00\x09\x00", FAILURE_UNKNOWN_ID),  # no function 9
            (b"\x00\x01\x01\x07\x00", FAILURE_ILLEGAL_APP_DATA),  # no argument 7
            (b"\x00\x01\x00", FAILURE_ILLEGAL_APP_DATA),  # watts missing
            (b"\x00\x02\x02\x01\x01\x01\x02", FAILURE_ILLEGAL_APP_DATA),  # times twice
            (b"\x00\x03\x00\x00", FAILURE_ILLEGAL_APP_DATA),  # trailing octet
        ):
            tx = loop.run_async(lambda d=data: loop.ground.send(APID, 8, 1, d))
            self.assertEqual(failure(tx)[:2], (1, code))
        self.assertEqual(heater.calls, [])
        self.assertEqual(loop.app.failures, {9: 1, 5: 5})

    def test_malformed_function_tables(self):
        for bad in (
            [{"id": 1, "name": "A.b"}, {"id": 1, "name": "A.c"}],
            [{"id": 1, "name": "A.b"}, {"id": 2, "name": "A.b"}],
            [{"id": 1, "name": "A.b", "arguments": [{"id": 1, "name": "x", "type": "nope"}]}],
            [{"id": 1, "name": "A.b", "arguments": [{"id": 300, "name": "x", "type": "bool"}]}],
            [{"name": "A.b"}],
        ):
            doc = json.loads(SDB)
            doc["functions"] = bad
            with self.assertRaises(SdbError):
                functions(Sdb(doc))
        with self.assertRaises(KeyError):
            FunctionUser({}).pack("Nope.nothing")


if __name__ == "__main__":
    unittest.main()


class TestLabels(unittest.TestCase):
    """An argument or an event field with an enumeration takes and shows its labels."""

    def db(self):
        doc = json.loads(SDB)
        doc["functions"] = [
            {"id": 9, "name": "Heater.mode", "arguments": [{"id": 1, "name": "mode",
             "type": "uint8", "enumeration": {"0": "OFF", "2": "ECO"}}]},
        ]  # fmt: skip
        doc["events"] = [{"name": "heater.mode", "id": 77, "severity": "info", "data": [
            {"name": "old", "type": "uint8", "enumeration": {"0": "OFF", "2": "ECO"}},
            {"name": "watts", "type": "uint8"}]}]  # fmt: skip
        return Sdb(doc)

    def test_a_label_is_sent_as_its_number(self):
        user = FunctionUser(functions(self.db()))
        self.assertEqual(user.pack("Heater.mode", {"mode": "ECO"}), user.pack(9, {"mode": 2}))
        self.assertEqual(user.pack(9, {1: "OFF"}), user.pack(9, {1: 0}))
        with self.assertRaises(ValueError) as e:
            user.pack(9, {"mode": "HOT"})
        said = str(e.exception)
        self.assertTrue("no label 'HOT'" in said and "OFF" in said and "ECO" in said, said)

    def test_an_event_field_shows_its_label(self):
        ev = self.db().event("heater.mode")
        values = ev.unpack(ev.pack({"old": 2, "watts": 2}))
        self.assertEqual(values, {"old": 2, "watts": 2})
        self.assertEqual(ev.labelled(values), {"old": "ECO", "watts": 2})
        self.assertEqual(ev.labelled({"old": 5, "watts": 1}), {"old": 5, "watts": 1})

    def test_a_bad_enumeration_is_a_database_error(self):
        doc = json.loads(SDB)
        arg = {"id": 1, "name": "mode", "type": "uint8", "enumeration": {"x": "OFF"}}
        doc["functions"] = [{"id": 9, "name": "Heater.mode", "arguments": [arg]}]
        self.assertRaises(SdbError, Sdb, doc)
