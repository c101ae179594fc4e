"""The spacecraft database: loading, lookups, unique ids, interface checks."""

import unittest

from obsw.il.interface import CONFIGURATION, DATA, INFO, Attribute, Event, Interface
from obsw.pus.sdb import SdbError, loads
from pus_loop import SDB


def variant(old, new):
    return SDB.replace(old, new, 1)


class TestSdb(unittest.TestCase):
    def test_load(self):
        db = loads(SDB)
        self.assertEqual(db.mission, "test")
        self.assertEqual(db.apid("pus"), 10)
        self.assertEqual(db.components, ["Panel"])
        p = db.parameter("Panel.speed")
        self.assertEqual((p.id, p.writable, p.type.name), (2, True, "float32"))
        self.assertIs(db.parameter(2), p)
        self.assertEqual(db.parameter("count").component, None)
        e = db.event("Panel.stuck")
        self.assertEqual((e.id, e.severity), (2, 4))
        self.assertEqual(e.unpack(e.pack(5)), {"code": 5})
        self.assertEqual(e.pack({"code": 1}), b"\x00\x01")
        self.assertEqual(db.event(3).pack(None), b"")
        self.assertEqual(
            db.housekeeping, [{"sid": 1, "interval": 2, "parameters": [1, 2, 3], "enabled": False}]
        )
        self.assertRaises(KeyError, db.parameter, "Panel.nothing")
        self.assertRaises(KeyError, db.event, 99)
        self.assertRaises(KeyError, db.apid, "cfdp")

    def test_ids_must_be_unique(self):
        for old, new in (
            ('"parameter": 2,', '"parameter": 1,'),  # parameter id
            ('"name": "count", "id": 100', '"name": "count", "id": 3'),
            ('"name": "stuck", "id": 2', '"name": "stuck", "id": 1'),  # event id
            ('"name": "low_one", "id": 3', '"name": "low_one", "id": 4'),
            ('"other": 11', '"other": 10'),  # APID
            ('"name": "speed"', '"name": "angle"'),  # attribute name
            ('"name": "stuck"', '"name": "moved"'),  # event name
        ):
            self.assertRaises(SdbError, loads, variant(old, new))

    def test_malformed(self):
        for old, new in (
            ('"type": "float32"', '"type": "float31"'),
            ('"type": "float32"', '"type": [3, 99]'),
            ('"severity": "high"', '"severity": "urgent"'),
            ('"other": 11', '"other": 4000'),
            ('"parameter": 2,', '"parameter": -2,'),
            ('"parameters": [1, 2, 3]', '"parameters": [1, 2, 999]'),
            ('{\n  "mission"', '[{\n  "mission"'),
        ):
            self.assertRaises(SdbError, loads, variant(old, new))
        self.assertRaises(SdbError, loads, "{")
        self.assertRaises(SdbError, loads, '{"components": [{"attributes": []}]}')

    def test_types(self):
        db = loads(
            '{"parameters": [{"name": "a", "id": 1, "type": [3, 14]},'
            '{"name": "b", "id": 2, "type": "int16"}]}'
        )
        self.assertEqual(db.parameter("a").type.bits, 32)
        self.assertEqual(db.parameter("b").type.pack(-2), b"\xff\xfe")

    def test_interfaces(self):
        db = loads(SDB)
        good = Interface(
            "Panel",
            1,
            [
                Attribute("angle", 1, DATA),
                Attribute("speed", 2, CONFIGURATION),
                Attribute("mode", 3, CONFIGURATION),
                Attribute("deployed", 4, DATA),
                Attribute("label", 5, CONFIGURATION),
                Event("moved", 6, INFO),
                Event("stuck", 7, INFO),
            ],
        )
        db.check_interfaces([good])
        read_only = Interface(
            "Panel", 1, [Attribute("angle", 1, DATA), Attribute("speed", 2, DATA)]
        )
        self.assertRaises(SdbError, db.check_interfaces, [read_only])
        missing = Interface("Panel", 1, [Attribute("speed", 2, CONFIGURATION)])
        self.assertRaises(SdbError, db.check_interfaces, [missing])


if __name__ == "__main__":
    unittest.main()


class SectionsTest(unittest.TestCase):
    """Every section of the database is parsed here, into typed objects."""

    DOC = {
        "components": [
            {
                "name": "Heater",
                "attributes": [{"name": "power", "parameter": 1, "type": "float32"}],
                "operations": [{"name": "set_power", "arguments": [{"name": "w", "unit": "W"}]}],
            }
        ],
        "functions": [
            {"id": 7, "name": "Heater.set_power",
             "arguments": [{"id": 1, "name": "w", "type": "float32"}]}
        ],
        "position_scheduling": {"parameter": "Heater.power"},
        "frames": {"tm_vcs": {"realtime": 0, "playback": 2}, "scid": 66},
        "nodes": [{"name": "CpduN", "node_id": 10, "definition": "cpdu_node.json"}],
    }  # fmt: skip

    def test_typed_sections_and_lookups(self):
        from obsw.pus.sdb import Sdb

        db = Sdb(self.DOC, "/data")
        f = db.function("Heater.set_power")
        self.assertIs(db.function(7), f)
        self.assertEqual(f.arguments, [(1, "w", "float32", None)])
        self.assertEqual(db.operations["Heater.set_power"].arguments, [("w", "W")])
        self.assertEqual(db.position_parameter.qualified, "Heater.power")
        self.assertEqual(db.tm_vcs, {"realtime": 0, "playback": 2})
        self.assertEqual(db.scid, 66)
        n = db.nodes["CpduN"]
        self.assertEqual((n.node_id, n.definition), (10, "/data/cpdu_node.json"))

    def test_bad_sections_are_sdb_errors(self):
        from obsw.pus.sdb import Sdb, SdbError

        for change in (
            {"warp": {}},
            {"functions": [{"id": 7, "name": "a"}, {"id": 7, "name": "b"}]},
            {"functions": [{"id": 1, "name": "f", "arguments": [{"id": 1, "name": "x"}]}]},
            {"position_scheduling": {"parameter": "Nowhere.x"}},
            {"nodes": [{"name": "A", "node_id": 200}]},
            {"nodes": [{"name": "A", "node_id": 3}, {"name": "B", "node_id": 3}]},
        ):
            doc = dict(self.DOC)
            doc.update(change)
            with self.assertRaises((SdbError, KeyError)):
                Sdb(doc)
