"""ST[06] object memory (TC[6,1], [6,3], [6,7], [6,17]), atomic loads (TC[6,11]) and write
protection (TC[6,15], [6,16]) honoured by every load, provider against user."""

import unittest

from obsw.cfdp.filestore import MemoryFilestore
from obsw.crc import crc16_ccitt
from obsw.pus.messages import (
    FAILURE_OUT_OF_BOUNDS,
    FAILURE_READBACK,
    FAILURE_REFUSED,
    FAILURE_UNKNOWN_ID,
    FAILURE_WRITE_PROTECTED,
)
from obsw.pus.sdb import SdbError, loads
from obsw.pus.services.s06_layouts import OBJECT_WHERE, ONE_OBJECT
from obsw.pus.services.s06_memory import (
    BytesMemory,
    MemoryManagement,
    MemoryUser,
    areas_from_sdb,
)
from obsw.pus.services.s23_files import FileManagement
from obsw.store import Store
from pus_loop import APID, Loop
from store_sim import SimFs

SDB = """{"memories": [
  {"id": 1, "name": "tables", "file": "mem/tables.bin", "start": 8192, "size": 128,
   "writable": true, "objects": [
     {"id": 1, "name": "gains", "offset": 16, "size": 32},
     {"id": 2, "name": "limits", "offset": 64, "size": 8}]},
  {"id": 2, "name": "rom", "start": 0, "size": 64, "objects": [{"id": 1, "size": 4}]}
]}"""


def make(store=None):
    fs = MemoryFilestore()
    areas = areas_from_sdb(loads(SDB), fs)
    loop = Loop(store=store)
    mem = loop.app.register(MemoryManagement(areas))
    loop.app.register(FileManagement(fs))
    user = loop.ground.register(MemoryUser())
    return loop, mem, user, fs


class Flaky(BytesMemory):
    """A memory whose octet 3 never changes (a stuck cell)."""

    def write(self, offset, data):
        keep = self.buf[3]
        super().write(offset, data)
        self.buf[3] = keep


class TestObjectMemory(unittest.TestCase):
    def test_objects_from_the_database(self):
        loop, mem, user, fs = make()
        self.assertEqual(mem.areas[1].objects, {1: ("gains", 16, 32), 2: ("limits", 64, 8)})
        self.assertEqual(mem.areas[2].objects, {1: ("object1", 0, 4)})
        for bad in (
            '{"memories": [{"id": 1, "size": 8, "objects": [{"id": 1, "offset": 4, "size": 5}]}]}',
            '{"memories": [{"id": 1, "size": 8, "objects": [{"id": 0, "size": 1}]}]}',
            '{"memories": [{"id": 1, "size": 8, "objects": [{"id": 2, "size": 1},'
            ' {"id": 2, "size": 1}]}]}',
        ):
            self.assertRaises(SdbError, loads, bad)

    def test_load_dump_check_by_object_and_offset(self):
        loop, mem, user, fs = make()
        tx = loop.run(user.load_object(APID, 1, 1, 4, b"gain"))
        self.assertTrue(tx.ok)
        self.assertEqual(bytes(fs.files["mem/tables.bin"][20:24]), b"gain")  # 16 + 4
        tx = loop.run(user.dump_object(APID, 1, 1, [(4, 4), (0, 2)]))
        self.assertEqual(loop.types()[-2:], [(6, 4), (1, 7)])
        self.assertEqual(
            tx.reply,
            {
                "memory": 1,
                "object": 1,
                "items": [
                    {"offset": 4, "data": b"gain", "checksum": crc16_ccitt(b"gain"), "ok": True},
                    {"offset": 0, "data": bytes(2), "checksum": crc16_ccitt(bytes(2)), "ok": True},
                ],
            },
        )
        tx = loop.run(user.check_object(APID, 1, 1, [(4, 4)]))
        self.assertEqual(loop.types()[-2:], [(6, 8), (1, 7)])
        self.assertEqual(
            tx.reply["items"], [{"offset": 4, "length": 4, "checksum": crc16_ccitt(b"gain")}]
        )
        # object 0 is the whole memory: offsets from its start
        tx = loop.run(user.dump_object(APID, 1, 0, [(20, 4)]))
        self.assertEqual(tx.reply["items"][0]["data"], b"gain")

    def test_check_a_whole_object(self):
        loop, mem, user, fs = make()
        loop.run(user.load_object(APID, 1, 2, 0, b"\x01\x02\x03\x04\x05\x06\x07\x08"))
        tx = loop.run(user.check_whole_object(APID, 1, 2))
        self.assertEqual(loop.types()[-2:], [(6, 18), (1, 7)])
        self.assertEqual(
            tx.reply,
            {
                "memory": 1,
                "object": 2,
                "length": 8,
                "checksum": crc16_ccitt(b"\x01\x02\x03\x04\x05\x06\x07\x08"),
            },
        )
        tx = loop.run(user.check_whole_object(APID, 1, 0))
        self.assertEqual(tx.reply["length"], 128)
        self.assertEqual(tx.reply["checksum"], crc16_ccitt(bytes(fs.files["mem/tables.bin"])))

    def test_object_failures(self):
        loop, mem, user, fs = make()
        tx = loop.run(user.dump_object(APID, 1, 9, [(0, 1)]))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, FAILURE_UNKNOWN_ID))
        self.assertEqual(tx.failure["data"], ONE_OBJECT.pack({"memory": 1, "object": 9}))
        tx = loop.run(user.check_whole_object(APID, 1, 3))
        self.assertEqual(tx.failure["code"], FAILURE_UNKNOWN_ID)
        tx = loop.run(user.load_object(APID, 1, 2, 6, b"abc"))  # 6 + 3 > 8
        self.assertEqual(tx.failure["code"], FAILURE_OUT_OF_BOUNDS)
        self.assertEqual(
            tx.failure["data"], OBJECT_WHERE.pack({"memory": 1, "object": 2, "offset": 6})
        )
        self.assertEqual(bytes(fs.files["mem/tables.bin"]), bytes(128))  # nothing written
        tx = loop.run(user.load_object(APID, 1, 1, 0, b"ab", checksum=5))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)
        tx = loop.run(user.load_object(APID, 2, 1, 0, b"ab"))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)  # ROM
        tx = loop.run(user.dump_object(APID, 1, 1, [(0, 2000)]))
        self.assertEqual(tx.failure["code"], FAILURE_OUT_OF_BOUNDS)


class TestAtomicLoad(unittest.TestCase):
    def test_atomic_load_replaces_the_image_whole(self):
        loop, mem, user, fs = make()
        tx = loop.run(user.load_atomic(APID, 1, 8192 + 100, b"atomic"))
        self.assertTrue(tx.ok)
        self.assertEqual(loop.types()[-1], (1, 7))
        self.assertEqual(bytes(fs.files["mem/tables.bin"][100:106]), b"atomic")
        self.assertEqual(len(fs.files["mem/tables.bin"]), 128)
        tx = loop.run(user.load_atomic(APID, 1, 8192 + 125, b"atomic"))
        self.assertEqual(tx.failure["code"], FAILURE_OUT_OF_BOUNDS)
        tx = loop.run(user.load_atomic(APID, 1, 8192, b"x", checksum=0))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)

    def test_atomic_load_that_does_not_read_back_is_undone(self):
        loop, mem, user, fs = make()
        mem.areas[5] = Flaky(8, 0, True, b"abcdefgh")
        tx = loop.run(user.load_atomic(APID, 5, 0, b"ABCDEFGH"))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (4, FAILURE_READBACK))
        self.assertEqual(bytes(mem.areas[5].buf), b"abcdefgh")  # all or nothing
        tx = loop.run(user.load(APID, 5, 0, b"ABCDEFGH"))  # a plain load says so too
        self.assertEqual(tx.failure["code"], FAILURE_READBACK)
        self.assertEqual(bytes(mem.areas[5].buf), b"ABCdEFGH")


class TestWriteProtection(unittest.TestCase):
    def test_every_load_honours_it(self):
        loop, mem, user, fs = make()
        fs.mkdir("up")
        fs.write_bytes("up/patch.bin", b"patch")
        self.assertTrue(loop.run(user.protect(APID, 1)).ok)
        for tx in (
            user.load(APID, 1, 8192, b"x"),
            user.load_object(APID, 1, 1, 0, b"x"),
            user.load_atomic(APID, 1, 8192, b"x"),
            user.load_by_reference(APID, 1, [(8192, "SAT:/up/patch.bin", crc16_ccitt(b"patch"))]),
            user.load_object_by_reference(
                APID, 1, 1, [(0, "SAT:/up/patch.bin", crc16_ccitt(b"patch"))]
            ),
        ):
            loop.run(tx)
            self.assertEqual(
                (tx.failure["stage"], tx.failure["code"]), (2, FAILURE_WRITE_PROTECTED)
            )
            self.assertEqual(tx.failure["data"], b"\x00\x01")
        self.assertEqual(bytes(fs.files["mem/tables.bin"]), bytes(128))
        self.assertTrue(loop.run(user.dump(APID, 1, [(8192, 4)])).ok)  # reading is allowed
        self.assertTrue(loop.run(user.unprotect(APID, 1)).ok)
        self.assertTrue(loop.run(user.load(APID, 1, 8192, b"x")).ok)
        tx = loop.run(user.protect(APID, 7))
        self.assertEqual(tx.failure["code"], FAILURE_UNKNOWN_ID)

    def test_protection_survives_a_restart(self):
        store = Store("ctx", SimFs())
        loop, mem, user, fs = make(store)
        loop.run(user.protect(APID, 1))
        loop2, mem2, user2, fs2 = make(store)
        self.assertEqual(mem2.protected, {1})
        tx = loop2.run(user2.load(APID, 1, 8192, b"x"))
        self.assertEqual(tx.failure["code"], FAILURE_WRITE_PROTECTED)


if __name__ == "__main__":
    unittest.main()
