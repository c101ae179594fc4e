"""The mission's ids on a reconfiguration board (mission.json): parsed, refused when wrong,
and used by the application (node id per role, SCID, essential MAP and HPTM VC)."""

import json
import os
import unittest

from obsw.reconfig import mission
from obsw.reconfig.app import ReconfigApp
from obsw.reconfig.hal import NOMINAL, REDUNDANT
from obsw.reconfig.models import ModelHal

DOC = {"scid": 341, "nodes": [20, 21], "essential_map": 40, "hptm_vc": 5}


def changed(**kw):
    doc = dict(DOC)
    doc.update(kw)
    return doc


class TestMissionFile(unittest.TestCase):
    def test_parse(self):
        self.assertEqual(
            mission.parse(DOC),
            {"scid": 341, "node_ids": (20, 21), "essential_map": 40, "hptm_vc": 5},
        )

    def test_every_mistake_names_its_key(self):
        cases = [
            ({"scid": 341, "nodes": [20, 21], "essential_map": 40}, "hptm_vc"),
            (changed(scid=1024), "scid"),
            (changed(scid=True), "scid"),
            (changed(nodes=[20]), "nodes"),
            (changed(nodes=[20, 20]), "nodes"),
            (changed(nodes=[0, 21]), "nodes"),
            (changed(essential_map=64), "essential_map"),
            (changed(hptm_vc=7), "hptm_vc"),
            (changed(node=1), "node"),
        ]
        for doc, key in cases:
            try:
                mission.parse(doc)
            except mission.MissionFileError as e:
                self.assertEqual(e.key, key)
                self.assertTrue(str(e).startswith("mission.json: " + key))
            else:
                self.fail("accepted %r" % (doc,))

    def test_load_from_a_file_and_none_without_one(self):
        path = "obsw-test-reconfig-mission.json"  # the working folder: a board's is its flash
        try:
            with open(path, "w") as f:
                f.write(json.dumps(DOC))
            self.assertEqual(mission.load(path)["node_ids"], (20, 21))
            with open(path, "w") as f:
                f.write("{not json")
            self.assertRaises(mission.MissionFileError, mission.load, path)
        finally:
            os.remove(path)
        self.assertIsNone(mission.load(path))


class TestAppTakesTheMissionsIds(unittest.TestCase):
    def test_node_id_per_role_scid_map_and_vc(self):
        options = mission.parse(DOC)
        for role, node in ((NOMINAL, 20), (REDUNDANT, 21)):
            # small EEPROM models: the test fits a board's heap too
            app = ReconfigApp(ModelHal(role, eeprom_size=4096), **options)
            self.assertEqual(app.node.responder.node_id, node)
            frames = app.essential.frames
            self.assertEqual((frames.scid, frames.essential_map), (341, 40))
            self.assertEqual(app.essential.hptm_vcid, 5)


if __name__ == "__main__":
    unittest.main()
