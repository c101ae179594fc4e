"""ST[06] loads by reference (TC[6,19], [6,21]) and dumps to file (TC[6,20], [6,22]) through
the onboard filestore of ST[23], and the abort of dumps in progress (TC[6,12])."""

import unittest

from obsw.cfdp.filestore import MemoryFilestore
from obsw.crc import crc16_ccitt
from obsw.pus.messages import (
    FAILURE_ABORTED,
    FAILURE_FILESTORE,
    FAILURE_OUT_OF_BOUNDS,
    FAILURE_PATH,
    FAILURE_REFUSED,
)
from obsw.pus.services.s06_memory import BytesMemory, MemoryManagement, MemoryUser
from obsw.pus.services.s23_files import FileManagement
from obsw.pus.services.s23_user import FileUser
from pus_loop import APID, Loop, asyncio

IMAGE = bytes(range(256)) * 40  # 10240 octets


def make(chunk=4096, files=True):
    fs = MemoryFilestore({"up/patch.bin": b"PATCH", "up/table.bin": b"T" * 8})
    fs.dirs.update(("up", "down"))
    loop = Loop()
    areas = {
        1: BytesMemory(len(IMAGE), 0x8000, True, IMAGE, objects={1: ("table", 512, 64)}),
        2: BytesMemory(16, 0, False),
    }
    mem = loop.app.register(MemoryManagement(areas, chunk=chunk))
    if files:
        loop.app.register(FileManagement(fs))
    user = loop.ground.register(MemoryUser())
    fuser = loop.ground.register(FileUser())
    return loop, mem, user, fuser, fs


def cycles(loop, make_tx, n=50):
    """Issue ``make_tx()`` in an event loop and run cycles until it is done; returns (the
    transaction, whether it was done before the first cycle)."""
    box = []

    async def main():
        tx = make_tx()
        loop.pump()
        box.extend((tx, tx.done))
        for _ in range(n):
            if tx.done:
                break
            loop.app.tick()
            await asyncio.sleep(0)
            await asyncio.sleep(0)
            loop.pump()

    asyncio.run(main())
    return box


class TestLoadByReference(unittest.TestCase):
    def test_raw_and_object_loads_from_files(self):
        loop, mem, user, fuser, fs = make()
        tx = loop.run(
            user.load_by_reference(
                APID, 1, [(0x8000 + 10, "SAT:/up/patch.bin", crc16_ccitt(b"PATCH"))]
            )
        )
        self.assertTrue(tx.ok)
        self.assertEqual(bytes(mem.areas[1].buf[10:15]), b"PATCH")
        tx = loop.run(
            user.load_object_by_reference(
                APID, 1, 1, [(8, "SAT:/up/table.bin", crc16_ccitt(b"T" * 8))]
            )
        )
        self.assertTrue(tx.ok)
        self.assertEqual(bytes(mem.areas[1].buf[520:528]), b"T" * 8)

    def test_refusals(self):
        loop, mem, user, fuser, fs = make()
        good = crc16_ccitt(b"PATCH")
        for items, code in (
            ([(0x8000, "SAT:/up/none.bin", good)], FAILURE_FILESTORE),
            ([(0x8000, "SAT:/up/../../x.bin", good)], FAILURE_PATH),
            ([(0x8000, "SAT:/up/patch.bin", good ^ 1)], FAILURE_REFUSED),
            ([(0x8000 + len(IMAGE) - 2, "SAT:/up/patch.bin", good)], FAILURE_OUT_OF_BOUNDS),
        ):
            tx = loop.run(user.load_by_reference(APID, 1, items))
            self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, code))
        tx = loop.run(user.load_object_by_reference(APID, 1, 1, [(62, "SAT:/up/patch.bin", good)]))
        self.assertEqual(tx.failure["code"], FAILURE_OUT_OF_BOUNDS)
        tx = loop.run(user.load_by_reference(APID, 2, [(0, "SAT:/up/patch.bin", good)]))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)  # read-only memory
        self.assertEqual(bytes(mem.areas[1].buf), IMAGE)  # nothing written

    def test_without_file_management(self):
        loop, mem, user, fuser, fs = make(files=False)
        tx = loop.run(user.load_by_reference(APID, 1, [(0x8000, "SAT:/up/patch.bin", 0)]))
        self.assertEqual(tx.failure["code"], FAILURE_FILESTORE)


class TestDumpToFile(unittest.TestCase):
    def test_small_dumps_complete_at_once(self):
        loop, mem, user, fuser, fs = make()
        tx = loop.run(user.dump_to_file(APID, 1, [(0x8000 + 256, 100, "SAT:/down/a.bin")]))
        self.assertTrue(tx.ok)
        self.assertEqual(bytes(fs.files["down/a.bin"]), IMAGE[256:356])
        tx = loop.run(user.dump_object_to_file(APID, 1, 1, [(0, 64, "SAT:/down/t.bin")]))
        self.assertTrue(tx.ok)
        self.assertEqual(bytes(fs.files["down/t.bin"]), IMAGE[512:576])
        # the dump and a load by reference of it give the image back
        mem.areas[1].buf[512:576] = bytes(64)
        crc = crc16_ccitt(IMAGE[512:576])
        tx = loop.run(user.load_object_by_reference(APID, 1, 1, [(0, "SAT:/down/t.bin", crc)]))
        self.assertTrue(tx.ok)
        self.assertEqual(bytes(mem.areas[1].buf), IMAGE)

    def test_large_dumps_go_chunk_by_chunk_and_complete_at_the_end(self):
        loop, mem, user, fuser, fs = make(chunk=1024)
        tx, done_at_once = cycles(
            loop, lambda: user.dump_to_file(APID, 1, [(0x8000, len(IMAGE), "SAT:/down/image.bin")])
        )
        self.assertFalse(done_at_once)  # started, completed cycles later
        self.assertEqual(loop.types().count((1, 7)), 1)
        self.assertTrue(tx.ok)
        self.assertEqual(bytes(fs.files["down/image.bin"]), IMAGE)
        self.assertFalse("down/image.bin.part" in fs.files)
        self.assertEqual(mem.dumps, 0)

    def test_abort_all_dumps(self):
        loop, mem, user, fuser, fs = make(chunk=1024)

        async def main():
            tx = user.dump_to_file(APID, 1, [(0x8000, len(IMAGE), "SAT:/down/image.bin")])
            loop.pump()
            for _ in range(3):
                loop.app.tick()
                await asyncio.sleep(0)
                loop.pump()
            self.assertEqual(mem.dumps, 1)
            abort = user.abort_dumps(APID)
            loop.pump()
            for _ in range(3):
                await asyncio.sleep(0)
                loop.pump()
            return tx, abort

        tx, abort = asyncio.run(main())
        self.assertTrue(abort.ok)
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (4, FAILURE_ABORTED))
        self.assertEqual(mem.aborted, 1)
        self.assertFalse("down/image.bin" in fs.files)
        self.assertFalse("down/image.bin.part" in fs.files)
        # with nothing in progress the abort has nothing to do
        self.assertTrue(loop.run(user.abort_dumps(APID)).ok)

    def test_locked_and_oversized_targets_are_refused(self):
        loop, mem, user, fuser, fs = make()
        fs.write_bytes("down/keep.bin", b"old")
        self.assertTrue(loop.run(fuser.lock(APID, "SAT:/down/keep.bin")).ok)
        tx = loop.run(user.dump_to_file(APID, 1, [(0x8000, 4, "SAT:/down/keep.bin")]))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, FAILURE_FILESTORE))
        self.assertEqual(bytes(fs.files["down/keep.bin"]), b"old")
        self.assertTrue(loop.run(fuser.create(APID, "SAT:/down/small.bin", 10)).ok)
        tx = loop.run(user.dump_to_file(APID, 1, [(0x8000, 11, "SAT:/down/small.bin")]))
        self.assertEqual(tx.failure["code"], FAILURE_FILESTORE)
        tx = loop.run(user.dump_to_file(APID, 1, [(0x8000, 4, "SAT:/nowhere/x.bin")]))
        self.assertEqual(tx.failure["code"], FAILURE_FILESTORE)
        tx = loop.run(
            user.dump_to_file(APID, 1, [(0x8000, 4, "SAT:/down/x"), (0x8000, 4, "SAT:/down/x")])
        )
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)


if __name__ == "__main__":
    unittest.main()
