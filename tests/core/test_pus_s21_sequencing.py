"""ST[21]: request sequences loaded, activated with exact delays, aborted, reported."""

import unittest

from obsw.crc import crc16_ccitt
from obsw.pus.services.s01_verification import (
    FAILURE_ILLEGAL_APP_DATA,
    FAILURE_REFUSED,
    FAILURE_UNKNOWN_ID,
)
from obsw.pus.services.s17_test import ServiceTest
from obsw.pus.services.s21_sequencing import CONTENT, RequestSequencing, RequestSequencingUser
from obsw.store import Store
from pus_loop import APID, Loop
from store_sim import SimFs


def make(store=None, **options):
    loop = Loop(store=store)
    seq = loop.app.register(RequestSequencing(**options))
    loop.app.register(ServiceTest())
    user = loop.ground.register(RequestSequencingUser())
    return loop, seq, user


def at(loop, t):
    loop.clock.advance(t - loop.clock.now())
    loop.app.tick()
    loop.pump()


def failure(tx):
    return (tx.failure["stage"], tx.failure["code"], tx.failure["data"]) if tx.failure else None


class TestSequencing(unittest.TestCase):
    def load_three(self, loop, user, name="warmup"):
        txs = [user.embed(APID, 17, 1)[1] for _ in range(3)]
        tx = loop.run(user.load(APID, name, [(txs[0], 2.0), (txs[1], 0.5), (txs[2], 1.0)]))
        self.assertTrue(tx.ok)
        return txs

    def test_activation_releases_requests_after_their_delays(self):
        loop, seq, user = make()
        txs = self.load_three(loop, user)
        self.assertTrue(loop.run(user.activate(APID, "warmup")).ok)  # at t = 1000
        at(loop, 1000.0)
        self.assertEqual([t.done for t in txs], [True, False, False])
        at(loop, 1001.99)
        self.assertFalse(txs[1].done)
        at(loop, 1002.0)
        self.assertEqual([t.ok for t in txs], [True, True, False])
        at(loop, 1002.5)
        self.assertTrue(txs[2].ok)
        tx = loop.run(user.report_status(APID))
        self.assertEqual(tx.reply["items"], [{"id": "warmup", "active": True}])
        at(loop, 1003.5)  # the last delay has passed: the sequence ends
        tx = loop.run(user.report_status(APID))
        self.assertEqual(tx.reply["items"], [{"id": "warmup", "active": False}])
        self.assertEqual((seq.released, seq.completed), (3, 1))

    def test_abort_and_abort_all(self):
        loop, seq, user = make()
        a = self.load_three(loop, user, "a")
        self.load_three(loop, user, "b")
        self.load_three(loop, user, "c")
        loop.run(user.activate(APID, "a"))
        loop.run(user.activate(APID, "b"))
        at(loop, 1000.0)
        self.assertTrue(loop.run(user.abort(APID, "a")).ok)
        at(loop, 1010.0)
        self.assertEqual([t.done for t in a], [True, False, False])
        loop.run(user.activate(APID, "c"))
        tx = loop.run(user.abort_all(APID))
        self.assertEqual(tx.reply, {"ids": ["c"]})  # b had ended
        tx = loop.run(user.abort(APID, "c"))
        self.assertEqual(failure(tx), (2, FAILURE_REFUSED, b"\x01c"))

    def test_content_checksum_and_unload(self):
        loop, seq, user = make()
        txs = self.load_three(loop, user)
        tx = loop.run(user.report_content(APID, "warmup"))
        self.assertEqual(tx.reply["id"], "warmup")
        self.assertEqual([i["delay"] for i in tx.reply["items"]], [2.0, 0.5, 1.0])
        self.assertEqual(tx.reply["items"][1]["request"], txs[1].tc.pack())
        tx = loop.run(user.checksum(APID, "warmup"))
        expected = crc16_ccitt(CONTENT.pack(seq.sequences["warmup"].content()))
        self.assertEqual(tx.reply, {"id": "warmup", "checksum": expected})
        self.assertTrue(loop.run(user.unload(APID, "warmup")).ok)
        self.assertEqual(seq.sequences, {})

    def test_bad_and_conflicting_requests(self):
        loop, seq, user = make(capacity=1, max_requests=2)
        a = user.embed(APID, 17, 1)[1]
        self.assertTrue(loop.run(user.load(APID, "s", [(a, 1.0)])).ok)
        loop.run(user.activate(APID, "s"))
        other = user.embed(99, 17, 1)[1]
        for tx, expected in (
            (user.load(APID, "s", [(a, 1.0)]), (2, FAILURE_REFUSED, b"\x01s")),  # active
            (user.load(APID, "t", [(a, 1.0)]), (2, FAILURE_REFUSED, b"\x01t")),  # capacity
            (user.activate(APID, "s"), (2, FAILURE_REFUSED, b"\x01s")),  # already active
            (user.unload(APID, "s"), (2, FAILURE_REFUSED, b"\x01s")),  # active
            (user.activate(APID, "x"), (2, FAILURE_UNKNOWN_ID, b"\x01x")),
            (user.checksum(APID, "x"), (2, FAILURE_UNKNOWN_ID, b"\x01x")),
        ):
            loop.run(tx)
            self.assertEqual(failure(tx), expected)
        loop.run(user.abort(APID, "s"))
        for items, expected in (
            ([(a, 1.0)] * 3, (2, FAILURE_REFUSED, b"\x01s")),  # too many requests
            ([], (2, FAILURE_REFUSED, b"\x01s")),
            ([(other, 1.0)], (2, FAILURE_UNKNOWN_ID, b"\x01s")),
            ([(a, -1.0)], (2, FAILURE_REFUSED, b"\x01s")),
        ):
            tx = loop.run(user.load(APID, "s", items))
            self.assertEqual(failure(tx), expected)
        for data in (b"\x01", b"\x01s\x00\x01" + bytes(8)):
            tx = loop.run(loop.ground.send(APID, 21, 1, data))
            self.assertEqual(failure(tx)[:2], (1, FAILURE_ILLEGAL_APP_DATA))

    def test_sequences_survive_a_restart_inactive(self):
        fs = SimFs()
        loop, seq, user = make(Store("/ctx", fs))
        txs = self.load_three(loop, user)
        loop.run(user.activate(APID, "warmup"))
        loop2, seq2, user2 = make(Store("/ctx", fs))
        s = seq2.sequences["warmup"]
        self.assertEqual((s.active, [d for _, d in s.items]), (False, [2 << 16, 1 << 15, 1 << 16]))
        self.assertEqual(s.items[0][0], txs[0].tc.pack())


if __name__ == "__main__":
    unittest.main()
