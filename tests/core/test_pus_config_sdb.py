"""The PUS packet layout declared in the spacecraft database's ``pus`` section."""

import unittest

from obsw.pus.config import DEFAULT, PusConfig, PusLayoutError, from_sdb
from obsw.pus.sdb import loads
from obsw.pus.tc import PusTc
from obsw.timecode import Cuc


def sdb(pus):
    return loads('{"mission": "t", "apids": {"pus": 10}, "pus": %s}' % pus)


class TestLayoutFromSdb(unittest.TestCase):
    def test_no_section_is_the_pus_c_default(self):
        self.assertIs(from_sdb(loads('{"apids": {"pus": 10}}')), DEFAULT)
        self.assertIs(from_sdb(sdb('{"source_id": 7}')), DEFAULT)  # an id, not a layout

    def test_declared_layout(self):
        cfg = from_sdb(
            sdb('{"source_id_size": 1, "destination_id_size": 0, "time": {"coarse": 4, "fine": 3},'
                ' "pec": false, "tm_spare": 1}')
        )  # fmt: skip
        want = PusConfig(
            source_id_size=1, destination_id_size=0, time=Cuc(4, 3), pec=False, tm_spare=1
        )
        self.assertEqual(cfg, want)
        self.assertIsNone(from_sdb(sdb('{"time": null}')).time)

    def test_a_tc_in_the_declared_layout(self):
        cfg = from_sdb(sdb('{"source_id_size": 1}'))
        raw = PusTc(10, 17, 1, b"", seq_count=3, source_id=0x33, config=cfg).pack()
        self.assertEqual(len(raw), 6 + 3 + 1 + 2)
        self.assertEqual(PusTc.unpack(raw, cfg).source_id, 0x33)

    def test_mistakes_name_the_key(self):
        for text, key in (
            ('{"source_id_size": 5}', ""),
            ('{"pec": 1}', "pec"),
            ('{"time": {"coarse": 5}}', "time"),
            ('{"time": {"fine": 2, "epoch": 0}}', "time.epoch"),
            ('{"time": 4}', "time"),
            ('{"layout": 1}', "layout"),
        ):
            try:
                from_sdb(sdb(text))
            except PusLayoutError as e:
                self.assertEqual(e.key, key)
                self.assertTrue(str(e).startswith("pus."))
            else:
                self.fail("accepted %s" % text)


if __name__ == "__main__":
    unittest.main()
