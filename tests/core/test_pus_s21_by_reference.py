"""ST[21] loading by reference (TC[21,2]) and load-and-activate (TC[21,8]): the sequence comes
from a file of the onboard filestore, named as in ST[23], locks and paths honoured."""

import unittest

from obsw.cfdp.filestore import MemoryFilestore
from obsw.pus.messages import FAILURE_FILESTORE, FAILURE_PATH, FAILURE_REFUSED
from obsw.pus.services.s17_test import ServiceTest
from obsw.pus.services.s21_sequencing import (
    CONTENT,
    ID,
    RequestSequencing,
    RequestSequencingUser,
)
from obsw.pus.services.s23_files import FileManagement
from obsw.pus.services.s23_user import FileUser
from pus_loop import APID, Loop


def make():
    fs = MemoryFilestore()
    fs.mkdir("seq")
    loop = Loop()
    seq = loop.app.register(RequestSequencing())
    loop.app.register(ServiceTest())
    loop.app.register(FileManagement(fs))
    user = loop.ground.register(RequestSequencingUser())
    files = loop.ground.register(FileUser())
    return loop, seq, user, files, fs


def at(loop, t):
    loop.clock.advance(t - loop.clock.now())
    loop.app.tick()
    loop.pump()


class TestByReference(unittest.TestCase):
    def write(self, user, fs, name, n=2):
        txs = [user.embed(APID, 17, 1)[1] for _ in range(n)]
        fs.write_bytes(name, user.sequence_file([(t, 1.0) for t in txs]))
        return txs

    def test_load_by_reference_then_activate(self):
        loop, seq, user, files, fs = make()
        txs = self.write(user, fs, "seq/warmup.seq")
        tx = loop.run(user.load_by_reference(APID, "warmup", "SAT:/seq/warmup.seq"))
        self.assertTrue(tx.ok)
        self.assertFalse(seq.sequences["warmup"].active)
        direct = loop.run(user.report_content(APID, "warmup"))
        self.assertEqual(len(direct.reply["items"]), 2)
        # the same content as a direct load of the same pairs
        self.assertEqual(
            loop.tm[-2].data,
            CONTENT.pack(
                {
                    "id": "warmup",
                    "items": [{"request": t.tc.pack(), "delay": (1, 0)} for t in txs],
                }
            ),
        )
        self.assertTrue(loop.run(user.activate(APID, "warmup")).ok)
        at(loop, loop.clock.now())
        self.assertEqual([t.ok for t in txs], [True, False])

    def test_load_and_activate(self):
        loop, seq, user, files, fs = make()
        txs = self.write(user, fs, "seq/go.seq")
        tx = loop.run(user.load_and_activate(APID, "go", "SAT:/seq/go.seq"))
        self.assertTrue(tx.ok)
        self.assertTrue(seq.sequences["go"].active)
        t0 = loop.clock.now()
        at(loop, t0)
        at(loop, t0 + 1.0)
        self.assertEqual([t.ok for t in txs], [True, True])
        # an active sequence is not loaded again, from a file or not
        tx = loop.run(user.load_and_activate(APID, "go", "SAT:/seq/go.seq"))
        self.assertEqual(
            (tx.failure["stage"], tx.failure["code"], tx.failure["data"]),
            (2, FAILURE_REFUSED, ID.pack({"id": "go"})),
        )

    def test_refusals(self):
        loop, seq, user, files, fs = make()
        self.write(user, fs, "seq/ok.seq")
        fs.write_bytes("seq/junk.seq", b"\x00\x01\x00")
        fs.write_bytes("seq/empty.seq", user.sequence_file([]))
        for path, code in (
            ("SAT:/seq/none.seq", FAILURE_FILESTORE),
            ("SAT:/seq/../../x.seq", FAILURE_PATH),
            ("GROUND:/x.seq", FAILURE_PATH),
            ("SAT:/seq/junk.seq", FAILURE_REFUSED),
            ("SAT:/seq/empty.seq", FAILURE_REFUSED),
        ):
            for tx in (
                user.load_by_reference(APID, "s", path),
                user.load_and_activate(APID, "s", path),
            ):
                loop.run(tx)
                self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, code))
        self.assertEqual(seq.sequences, {})
        self.assertTrue(loop.run(files.lock(APID, "SAT:/seq/ok.seq")).ok)
        self.assertTrue(loop.run(user.load_by_reference(APID, "s", "SAT:/seq/ok.seq")).ok)


if __name__ == "__main__":
    unittest.main()
