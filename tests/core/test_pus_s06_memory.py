"""ST[06]: load, dump and check raw memory of areas from the spacecraft database, provider
against user; bounds, checksums and write protection."""

import unittest

from obsw.cfdp.filestore import MemoryFilestore
from obsw.crc import crc16_ccitt
from obsw.pus.messages import FAILURE_OUT_OF_BOUNDS, FAILURE_REFUSED, FAILURE_UNKNOWN_ID
from obsw.pus.sdb import loads
from obsw.pus.services.s06_memory import (
    BytesMemory,
    MemoryManagement,
    MemoryUser,
    areas_from_sdb,
)
from pus_loop import APID, Loop

SDB = """{"memories": [
  {"id": 1, "name": "image", "file": "mem/image.bin", "start": 4096, "size": 256,
   "writable": true},
  {"id": 2, "name": "rom", "start": 0, "size": 64}
]}"""


def make(max_dump=1024):
    fs = MemoryFilestore()
    areas = areas_from_sdb(loads(SDB), fs)
    areas[3] = BytesMemory(16, 0x100, True, b"0123456789abcdef")
    loop = Loop()
    mem = loop.app.register(MemoryManagement(areas, max_dump))
    user = loop.ground.register(MemoryUser())
    return loop, mem, user, fs


class TestMemory(unittest.TestCase):
    def test_areas_from_the_database(self):
        loop, mem, user, fs = make()
        self.assertEqual(bytes(fs.files["mem/image.bin"]), bytes(256))
        self.assertEqual((mem.areas[1].start, mem.areas[1].size), (4096, 256))
        self.assertFalse(mem.areas[2].writable)

    def test_load_dump_check_of_a_file_backed_image(self):
        loop, mem, user, fs = make()
        tx = loop.run(user.load(APID, 1, 4096 + 10, b"hello"))
        self.assertTrue(tx.ok)
        self.assertEqual(bytes(fs.files["mem/image.bin"][8:17]), b"\x00\x00hello\x00\x00")
        tx = loop.run(user.dump(APID, 1, [(4096 + 10, 5), (4096, 2)]))
        self.assertEqual(
            tx.reply["items"],
            [
                {"address": 4106, "data": b"hello", "checksum": crc16_ccitt(b"hello"), "ok": True},
                {
                    "address": 4096,
                    "data": b"\x00\x00",
                    "checksum": crc16_ccitt(b"\x00\x00"),
                    "ok": True,
                },
            ],
        )
        tx = loop.run(user.check(APID, 1, [(4096, 256)]))
        expected = crc16_ccitt(bytes(fs.files["mem/image.bin"]))
        self.assertEqual(
            tx.reply,
            {"memory": 1, "items": [{"address": 4096, "length": 256, "checksum": expected}]},
        )
        self.assertEqual(loop.types()[-2:], [(6, 10), (1, 7)])

    def test_check_in_slices_matches_whole(self):
        loop, mem, user, fs = make()
        big = BytesMemory(5000, 0, True, bytes(range(250)) * 20)
        mem.areas[9] = big
        tx = loop.run(user.check(APID, 9, [(0, 5000), (100, 0)]))
        self.assertEqual(tx.reply["items"][0]["checksum"], crc16_ccitt(big.buf))
        self.assertEqual(tx.reply["items"][1]["checksum"], crc16_ccitt(b""))

    def test_bounds(self):
        loop, mem, user, fs = make()
        for tx in (
            user.dump(APID, 1, [(4095, 2)]),
            user.dump(APID, 1, [(4096 + 250, 7)]),
            user.check(APID, 3, [(0x100, 17)]),
            user.load(APID, 3, 0x10F, b"xy"),
        ):
            loop.run(tx)
            self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, FAILURE_OUT_OF_BOUNDS))
        self.assertEqual(tx.failure["data"], b"\x00\x03\x00\x00\x01\x0f")
        self.assertEqual(bytes(mem.areas[3].buf), b"0123456789abcdef")  # nothing written

    def test_refusals(self):
        loop, mem, user, fs = make(max_dump=8)
        tx = loop.run(user.load(APID, 2, 0, b"x"))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)  # read-only
        tx = loop.run(user.load(APID, 3, 0x100, b"ab", checksum=1))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)  # checksum mismatch
        tx = loop.run(user.dump(APID, 7, [(0, 1)]))
        self.assertEqual(tx.failure["code"], FAILURE_UNKNOWN_ID)
        tx = loop.run(user.dump(APID, 3, [(0x100, 9)]))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)  # over the largest dump
        self.assertTrue(loop.run(user.dump(APID, 3, [(0x100, 8)])).ok)


if __name__ == "__main__":
    unittest.main()
