"""ST[20]: report and set parameter values, provider against user."""

import json
import unittest

from obsw.pus.parameters import ParameterPool
from obsw.pus.sdb import Sdb
from obsw.pus.services.s01_verification import (
    FAILURE_EXECUTION,
    FAILURE_OUT_OF_BOUNDS,
    FAILURE_OUT_OF_RANGE,
    FAILURE_REFUSED,
    FAILURE_UNKNOWN_ID,
)
from obsw.pus.services.s06_memory import BytesMemory
from obsw.pus.services.s20_parameters import ParameterManagement, ParameterUser, RangeError
from obsw.store import Store
from pus_loop import APID, SDB, Loop, sdb
from store_sim import SimFs


def ranged():
    """The test database with a calibrated, ranged uint16 and a labelled mode."""
    doc = json.loads(SDB)
    attrs = doc["components"][0]["attributes"]
    attrs[2]["enumeration"] = {"0": "OFF", "1": "IDLE", "2": "TRACK"}
    attrs[2]["range"] = [0, 2]
    attrs.append(
        {
            "name": "heater",
            "parameter": 6,
            "type": "uint16",
            "unit": "degC",
            "writable": True,
            "calibration": {"polynomial": [-50, 0.05]},
            "range": [-10, 40],
        }
    )
    return Sdb(doc)


def make(db=None, memories=None, store=None, engineering=False):
    db = db or sdb()
    loop = Loop(store=store)
    pool = ParameterPool(db)
    pool.values.update({1: 12.5, 2: 3.0, 3: 2})
    counter = [41]
    pool.provide("count", lambda: counter[0])
    loop.app.register(ParameterManagement(pool, memories))
    user = loop.ground.register(
        ParameterUser(
            lambda pid: db.parameter(pid).type,
            lambda pid: db.parameter(pid).qualified,
            lambda key: db.parameter(key).id,
            db.parameter if engineering else None,
        )
    )
    return loop, pool, user


class TestParameters(unittest.TestCase):
    def test_report_values(self):
        loop, pool, user = make()
        tx = loop.run(
            user.report(
                APID, ["Panel.angle", 2, "Panel.mode", "Panel.deployed", "Panel.label", "count"]
            )
        )
        self.assertTrue(tx.ok)
        self.assertEqual(
            tx.reply["values"],
            {
                "Panel.angle": 12.5,
                "Panel.speed": 3.0,
                "Panel.mode": 2,
                "Panel.deployed": False,
                "Panel.label": "",
                "count": 41,
            },
        )
        self.assertEqual(loop.types(), [(1, 1), (1, 3), (20, 2), (1, 7)])

    def test_report_unknown_parameter(self):
        loop, pool, user = make()
        tx = loop.run(user.report(APID, [1, 999]))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, FAILURE_UNKNOWN_ID))
        self.assertEqual(tx.failure["data"], b"\x03\xe7")

    def test_a_value_its_type_cannot_carry_is_a_failure_naming_it_and_why(self):
        loop, pool, user = make()
        pool.values[3] = 70000  # Panel.mode is a uint8: a component wider than its database
        tx = loop.run(user.report(APID, ["Panel.angle", "Panel.mode"]))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (4, FAILURE_EXECUTION))
        data = bytes(tx.failure["data"])
        self.assertEqual(data[:2], b"\x00\x03")
        self.assertTrue(data[2:].decode().startswith("70000: "), data)
        self.assertEqual([t for t in loop.types() if t[0] == 20], [])

    def test_set_values(self):
        loop, pool, user = make()
        tx = loop.run_async(
            lambda: user.set(APID, {"Panel.speed": 7.25, "Panel.mode": 9, "Panel.label": "east"})
        )
        self.assertTrue(tx.ok)
        self.assertEqual((pool.get(2), pool.get(3), pool.get(5)), (7.25, 9, "east"))
        tx = loop.run(user.report(APID, ["Panel.speed", "Panel.label"]))
        self.assertEqual(tx.reply["values"], {"Panel.speed": 7.25, "Panel.label": "east"})

    def test_set_read_only_is_refused(self):
        loop, pool, user = make()
        tx = loop.run_async(lambda: user.set(APID, {"Panel.mode": 1, "Panel.angle": 1.0}))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, FAILURE_REFUSED))
        self.assertEqual(pool.get(3), 2)  # nothing changed

    def test_set_unknown_parameter_fails_acceptance(self):
        loop, pool, user = make()
        tx = loop.run_async(lambda: loop.ground.send(APID, 20, 3, b"\x01\x03\xe7\x00"))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (1, 5))


class TestRange(unittest.TestCase):
    def test_out_of_range_is_refused_on_board_and_nothing_changes(self):
        loop, pool, user = make(ranged())
        pool.values[6] = 1400
        tx = loop.run_async(lambda: user.set(APID, {"Panel.speed": 5.0, "Panel.heater": 2000}))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, FAILURE_OUT_OF_RANGE))
        self.assertEqual(tx.failure["data"], b"\x00\x06")
        self.assertEqual((pool.get(2), pool.get(6)), (3.0, 1400))  # all or nothing
        tx = loop.run_async(lambda: user.set(APID, {"Panel.heater": 1600}))  # 30 degC
        self.assertTrue(tx.ok)
        self.assertEqual(pool.get(6), 1600)

    def test_the_edges_of_the_range_are_in(self):
        loop, pool, user = make(ranged())
        for raw in (800, 1800):  # -10 and 40 degC
            self.assertTrue(loop.run_async(lambda r=raw: user.set(APID, {6: r})).ok)
        for raw in (799, 1801):
            tx = loop.run_async(lambda r=raw: user.set(APID, {6: r}))
            self.assertEqual(tx.failure["code"], FAILURE_OUT_OF_RANGE)

    def test_ground_converts_engineering_values_and_checks_the_range(self):
        loop, pool, user = make(ranged(), engineering=True)
        tx = loop.run_async(lambda: user.set(APID, {"Panel.heater": 20.0, "Panel.mode": "TRACK"}))
        self.assertTrue(tx.ok)
        self.assertEqual((pool.get(6), pool.get(3)), (1400, 2))
        self.assertTrue(loop.run_async(lambda: user.set(APID, {6: 1500}, raw=True)).ok)
        self.assertEqual(pool.get(6), 1500)
        sent = len(loop.tc)
        self.assertRaises(RangeError, user.set, APID, {"Panel.heater": 45.0})
        self.assertRaises(RangeError, user.set, APID, {"Panel.heater": 2000}, True)
        self.assertRaises(ValueError, user.set, APID, {"Panel.mode": "PARK"})
        loop.pump()
        self.assertEqual(len(loop.tc), sent)  # nothing went out


def memory_db():
    doc = json.loads(SDB)
    doc["memories"] = [{"id": 1, "name": "ram", "start": 4096, "size": 64, "writable": True}]
    return Sdb(doc)


class TestDefinitions(unittest.TestCase):
    def setUp(self):  # object 5 ("table") is octets 16..23 of the area
        self.ram = BytesMemory(64, start=4096, objects={5: ("table", 16, 8)})

    def test_report_definitions_of_database_parameters(self):
        loop, pool, user = make(memory_db(), {1: self.ram})
        tx = loop.run(user.report_definitions(APID, ["Panel.speed", 100]))
        self.assertTrue(tx.ok)
        self.assertEqual(
            tx.reply["definitions"],
            [
                {
                    "id": 2,
                    "kind": "component",
                    "memory": 0,
                    "object": 0,
                    "address": 0,
                    "name": "Panel.speed",
                },
                {
                    "id": 100,
                    "kind": "component",
                    "memory": 0,
                    "object": 0,
                    "address": 0,
                    "name": "count",
                },
            ],
        )
        tx = loop.run(user.report_definitions(APID))
        self.assertEqual([d["id"] for d in tx.reply["definitions"]], [1, 2, 3, 4, 5, 100])

    def test_raw_and_object_memory_definitions_move_the_value(self):
        loop, pool, user = make(memory_db(), {1: self.ram})
        tx = loop.run(user.change_raw_definitions(APID, [("Panel.speed", 1, 4100)]))
        self.assertTrue(tx.ok)
        items = [("Panel.mode", 1, 0, 8), ("count", 1, 5, 4)]  # object 0: the whole area
        tx = loop.run(user.change_object_definitions(APID, items))
        self.assertTrue(tx.ok)
        self.assertTrue(loop.run_async(lambda: user.set(APID, {2: 2.5, 3: 7})).ok)
        self.assertEqual(self.ram.read(4, 4), b"\x40\x20\x00\x00")  # 2.5 as float32
        self.assertEqual(self.ram.read(8, 1), b"\x07")
        self.ram.write(8, b"\x09")
        self.ram.write(20, b"\x00\x00\x01\x02")  # object 5 starts at 16
        self.assertEqual((pool.get(3), pool.get(100)), (9, 258))  # every reader reads there
        tx = loop.run(user.report(APID, ["Panel.speed", "Panel.mode"]))
        self.assertEqual(tx.reply["values"], {"Panel.speed": 2.5, "Panel.mode": 9})
        tx = loop.run(user.report_definitions(APID, [2, 3, 100]))
        rows = [
            (d["kind"], d["memory"], d["object"], d["address"]) for d in tx.reply["definitions"]
        ]
        self.assertEqual(
            rows,
            [("raw memory", 1, 0, 4100), ("object memory", 1, 0, 8), ("object memory", 1, 5, 4)],
        )

    def test_bad_definitions_fail_the_start_and_change_nothing(self):
        loop, pool, user = make(memory_db(), {1: self.ram})
        cases = (
            ([(2, 1, 4096), (999, 1, 4096)], FAILURE_UNKNOWN_ID, b"\x03\xe7"),
            ([(2, 1, 4096), (3, 7, 4096)], FAILURE_UNKNOWN_ID, b"\x00\x07"),
            ([(2, 1, 4096), (2, 1, 4158)], FAILURE_OUT_OF_BOUNDS, b"\x00\x01\x00\x00\x10\x3e"),
            ([(2, 1, 4095)], FAILURE_OUT_OF_BOUNDS, b"\x00\x01\x00\x00\x0f\xff"),
            ([(5, 1, 4096)], FAILURE_REFUSED, b"\x00\x05"),  # a string has no fixed size
        )
        for items, code, data in cases:
            tx = loop.run(user.change_raw_definitions(APID, items))
            self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, code))
            self.assertEqual(tx.failure["data"], data)
        cases = (
            ([(2, 1, 9, 0)], FAILURE_UNKNOWN_ID, b"\x00\x01\x00\x09"),  # no object 9
            ([(2, 1, 5, 5)], FAILURE_OUT_OF_BOUNDS, b"\x00\x01\x00\x05\x00\x00\x00\x05"),
            ([(2, 1, 0, 61)], FAILURE_OUT_OF_BOUNDS, b"\x00\x01\x00\x00\x00\x00\x00\x3d"),
        )
        for items, code, data in cases:
            tx = loop.run(user.change_object_definitions(APID, items))
            self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, code))
            self.assertEqual(tx.failure["data"], data)
        tx = loop.run(user.report_definitions(APID, [2]))
        self.assertEqual(tx.reply["definitions"][0]["kind"], "component")

    def test_definitions_persist(self):
        store = Store("/ctx", SimFs())
        loop, pool, user = make(memory_db(), {1: self.ram}, store)
        self.assertTrue(loop.run(user.change_object_definitions(APID, [(2, 1, 0, 12)])).ok)
        self.ram.write(12, b"\x3f\x80\x00\x00")
        loop2, pool2, user2 = make(memory_db(), {1: self.ram}, store)
        self.assertEqual(pool2.get(2), 1.0)
        tx = loop2.run(user2.report_definitions(APID, [2]))
        self.assertEqual(tx.reply["definitions"][0]["address"], 12)

    def test_saved_definitions_wait_for_their_memory_area(self):
        store = Store("/ctx", SimFs())
        loop, pool, user = make(memory_db(), {1: self.ram}, store)
        self.assertTrue(loop.run(user.change_raw_definitions(APID, [(2, 1, 4096)])).ok)
        self.ram.write(0, b"\x3f\x80\x00\x00")
        loop2, pool2, user2 = make(memory_db(), None, store)
        self.assertEqual(pool2.get(2), 3.0)  # the component's value until the area is served
        loop2.app.services[20].use_memories({1: self.ram})
        self.assertEqual(pool2.get(2), 1.0)
        tx = loop2.run(user2.report_definitions(APID, [2]))
        self.assertEqual(tx.reply["definitions"][0]["kind"], "raw memory")


if __name__ == "__main__":
    unittest.main()
