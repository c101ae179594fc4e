"""ST[06] scrubbing (TC[6,13], [6,14]): memories read back every cycle, a mirrored one repaired
from its good copy, damage no copy can repair reported once, loads taken as the reference."""

import unittest

from obsw.cfdp.filestore import MemoryFilestore
from obsw.pus.messages import FAILURE_UNKNOWN_ID
from obsw.pus.sdb import loads
from obsw.pus.services.s05_events import EventReporting
from obsw.pus.services.s06_areas import MirroredMemory
from obsw.pus.services.s06_layouts import WHERE
from obsw.pus.services.s06_memory import (
    EVENT_SCRUB_REPAIRED,
    EVENT_SCRUB_UNCORRECTABLE,
    BytesMemory,
    MemoryManagement,
    MemoryUser,
    areas_from_sdb,
)
from obsw.pus.services.s06_scrub import REPAIRED, UNCORRECTABLE, Scrub
from obsw.store import Store
from pus_loop import APID, Loop
from store_sim import SimFs

SDB = """{"memories": [
  {"id": 1, "name": "sgm", "file": "sgm/a.bin", "mirror": "sgm/b.bin", "start": 0,
   "size": 1000, "writable": true},
  {"id": 2, "name": "ram", "start": 4096, "size": 512, "writable": true}
]}"""


def make(store=None, fs=None):
    fs = fs if fs is not None else MemoryFilestore()
    areas = areas_from_sdb(loads(SDB), fs)
    loop = Loop(store=store)
    loop.app.register(EventReporting())
    mem = loop.app.register(MemoryManagement(areas, scrub_block=100, scrub_blocks=5))
    user = loop.ground.register(MemoryUser())
    return loop, mem, user, fs


def events(loop):
    return [(tm.subtype, tm.data) for tm in loop.tm if tm.service == 5]


def where(memory, address):
    return WHERE.pack({"memory": memory, "address": address})


class TestScrub(unittest.TestCase):
    def test_a_pass_finds_nothing_in_good_memory(self):
        area = BytesMemory(1000, 0, True, bytes(range(250)) * 4)
        s = Scrub(area, 100)
        self.assertEqual(s.count, 10)
        self.assertEqual(s.step(25), [])
        self.assertEqual(s.passes, 1)  # ten blocks, at most one pass a step

    def test_last_block_may_be_short(self):
        area = BytesMemory(250, 0, True, b"x" * 250)
        s = Scrub(area, 100)
        self.assertEqual(s.count, 3)
        area.buf[249] = 0
        self.assertEqual(s.step(3), [(UNCORRECTABLE, 200)])

    def test_mirror_repairs_either_copy(self):
        a = BytesMemory(300, 0, True, b"a" * 300)
        b = BytesMemory(300, 0, True, b"a" * 300)
        s = Scrub(MirroredMemory(a, b), 100)
        a.buf[150] = 0  # the first copy is hit
        b.buf[20] = 1  # the second too, elsewhere
        self.assertEqual(s.step(3), [(REPAIRED, 0), (REPAIRED, 100)])
        self.assertEqual((bytes(a.buf), bytes(b.buf)), (b"a" * 300, b"a" * 300))
        self.assertEqual(s.repaired, 2)
        a.buf[250] = b.buf[250] = 7  # both copies of one block: nothing to repair from
        self.assertEqual(s.step(3), [(UNCORRECTABLE, 200)])
        self.assertEqual(s.step(3), [])  # reported once
        s.loaded(250, 1)  # until a load makes it the reference
        self.assertEqual(s.bad, set())

    def test_refs_of_another_size_are_refused(self):
        self.assertRaises(ValueError, Scrub, BytesMemory(300), 100, [0, 0])


class TestScrubbingService(unittest.TestCase):
    def test_enable_repair_report_disable(self):
        loop, mem, user, fs = make()
        self.assertTrue(loop.run(user.load(APID, 1, 0, b"safeguard")).ok)
        self.assertEqual(bytes(fs.files["sgm/b.bin"][:9]), b"safeguard")  # both copies
        self.assertTrue(loop.run(user.enable_scrubbing(APID, 1)).ok)
        self.assertTrue(loop.run(user.enable_scrubbing(APID, 2)).ok)
        fs.files["sgm/b.bin"][4] ^= 0x10  # a bit flips in the second EEPROM
        fs.files["sgm/a.bin"][930] ^= 0x01  # and in the first, at the end
        mem.areas[2].buf[300] = 0xEE  # RAM has no second copy
        for _ in range(2):
            loop.app.tick()
        loop.pump()
        self.assertEqual(fs.files["sgm/b.bin"][:9], bytearray(b"safeguard"))
        self.assertEqual(fs.files["sgm/a.bin"][930], 0)
        self.assertEqual(
            events(loop),
            [
                (2, b"\xff\x06" + where(1, 0)),
                (3, b"\xff\x07" + where(2, 4096 + 300)),
                (2, b"\xff\x06" + where(1, 900)),
            ],
        )
        self.assertEqual(mem.scrubs[1].repaired, 2)
        # a load through service 6 is the new reference: nothing reported
        self.assertTrue(loop.run(user.load(APID, 2, 4096 + 300, b"\x00")).ok)
        n = len(events(loop))
        for _ in range(4):
            loop.app.tick()
        loop.pump()
        self.assertEqual(len(events(loop)), n)
        self.assertTrue(loop.run(user.disable_scrubbing(APID, 2)).ok)
        self.assertEqual(sorted(mem.scrubs), [1])
        self.assertEqual(
            loop.run(user.enable_scrubbing(APID, 9)).failure["code"], FAILURE_UNKNOWN_ID
        )

    def test_references_survive_a_restart(self):
        store = Store("ctx", SimFs())
        loop, mem, user, fs = make(store)
        loop.run(user.enable_scrubbing(APID, 1))
        fs.files["sgm/a.bin"][0] ^= 0xFF  # while the process is down
        loop2, mem2, user2, fs2 = make(store, fs)
        self.assertEqual(sorted(mem2.scrubs), [1])
        loop2.app.tick()
        loop2.pump()
        self.assertEqual(events(loop2), [(2, b"\xff\x06" + where(1, 0))])
        self.assertEqual(fs.files["sgm/a.bin"][0], 0)
        self.assertEqual((EVENT_SCRUB_REPAIRED, EVENT_SCRUB_UNCORRECTABLE), (0xFF06, 0xFF07))


if __name__ == "__main__":
    unittest.main()
