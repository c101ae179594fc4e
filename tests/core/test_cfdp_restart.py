"""CFDP transactions survive a restart: state persisted atomically through the filestore."""

import unittest

from cfdp_sim import Link, make_pair, payload
from obsw.cfdp.defs import FILE_RETAINED, NO_ERROR, UNACKNOWLEDGED
from obsw.cfdp.entity import CfdpEntity

DATA = payload(6000)


def restarted(ent):
    """A new entity over the same filestore and MIB, as after a process restart."""
    fresh = CfdpEntity(ent.mib, ent.fs, persist=True, checkpoint=ent.checkpoint_bytes)
    return fresh


class TestRestart(unittest.TestCase):
    def setup(self, **kw):
        a, b = make_pair(files_a={"src.bin": DATA}, persist=True, **kw)
        a.checkpoint_bytes = b.checkpoint_bytes = 1000
        tid = a.put(2, "src.bin", "dst.bin")
        return a, b, tid

    def finish_ok(self, link, ents):
        self.assertTrue(link.run())
        b = ents[1]
        self.assertEqual(bytes(b.fs.files["dst.bin"]), DATA)
        for side in (0, 1):
            conds = [i.info["condition"] for i in link.finished(side)]
            self.assertEqual(conds, [NO_ERROR])
        self.assertEqual(link.finished(0)[0].info["file_status"], FILE_RETAINED)
        for e in ents:
            self.assertEqual(e.tx, {})
            names = [n for n in e.fs.listdir(".cfdp") if n.endswith(".json")]
            self.assertEqual(names, [])

    def test_receiver_restarts_mid_transfer(self):
        a, b, tid = self.setup()
        link = Link(a, b, seed=3, loss=0.05)
        link.run(until=lambda: b.find(tid) is not None and b.find(tid).received > 2500)
        b2 = restarted(b)
        self.assertEqual(b2.restore(link.now), 1)
        link.ents[1] = b2
        self.finish_ok(link, [a, b2])

    def test_receiver_restarts_after_eof(self):
        a, b, tid = self.setup()
        link = Link(
            a, b, seed=5, drop=lambda side, pdu: side == 0 and pdu[0] & 0x10 and pdu[-1] & 3 == 0
        )
        link.run(until=lambda: b.find(tid) is not None and b.find(tid).eof is not None)
        b2 = restarted(b)
        b2.restore(link.now)
        link.ents[1] = b2
        link.drop = None
        self.finish_ok(link, [a, b2])

    def test_sender_restarts_mid_transfer(self):
        a, b, tid = self.setup()
        link = Link(a, b, seed=6, loss=0.05)
        link.run(until=lambda: a.find(tid) is not None and a.find(tid).progress > 3000)
        a2 = restarted(a)
        self.assertEqual(a2.restore(link.now), 1)
        link.ents[0] = a2
        self.finish_ok(link, [a2, b])
        # the restarted entity does not reuse the transaction sequence number
        self.assertTrue(a2.put(2, "src.bin", "again.bin")[1] > tid[1])

    def test_both_restart_class1(self):
        a, b = make_pair(files_a={"src.bin": DATA}, persist=True, mode=UNACKNOWLEDGED)
        a.checkpoint_bytes = b.checkpoint_bytes = 1000
        tid = a.put(2, "src.bin", "dst.bin", closure=True)
        link = Link(a, b)
        link.run(until=lambda: b.find(tid) is not None and b.find(tid).received > 2000)
        a2 = restarted(a)
        b2 = restarted(b)
        a2.restore(link.now)
        b2.restore(link.now)
        link.ents = [a2, b2]
        link.run()
        self.assertEqual(bytes(b2.fs.files["dst.bin"]), DATA)

    def test_suspended_state_survives(self):
        a, b, tid = self.setup()
        link = Link(a, b)
        link.step()
        a.suspend(tid, link.now)
        a2 = restarted(a)
        a2.restore(link.now)
        self.assertTrue(a2.find(tid).suspended)
        a2.resume(tid, link.now)
        link.ents[0] = a2
        link.run()
        self.assertEqual(bytes(b.fs.files["dst.bin"]), DATA)


if __name__ == "__main__":
    unittest.main()
