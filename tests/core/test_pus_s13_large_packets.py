"""ST[13]: large packet transfer both ways, provider against user; reception timeouts and
aborts on either side."""

import unittest

from obsw.pus.messages import FAILURE_REFUSED
from obsw.pus.services.s13_large_packets import (
    ABORT_COMMANDED,
    ABORT_SEQUENCE,
    ABORT_TIMEOUT,
    ABORT_TOO_LARGE,
    LargePacketTransfer,
    LargePacketUser,
    split,
)
from obsw.pus.services.s17_test import ServiceTest
from obsw.pus.tc import PusTc
from obsw.pus.tm import PusTm
from pus_loop import APID, Loop


def make(**kw):
    loop = Loop()
    loop.app.register(ServiceTest())
    large = loop.app.register(LargePacketTransfer(**kw))
    user = loop.ground.register(LargePacketUser(part_size=kw.get("part_size", 256)))
    return loop, large, user


class TestSplit(unittest.TestCase):
    def test_parts(self):
        self.assertEqual(split(b"abcdefg", 3), [b"abc", b"def", b"g"])
        self.assertEqual(split(b"ab", 10), [b"a", b"b"])
        self.assertEqual(split(b"", 10), [b"", b""])
        self.assertEqual(b"".join(split(bytes(range(200)), 7)), bytes(range(200)))


class TestUplink(unittest.TestCase):
    def test_a_large_tc_is_put_back_together_and_executed(self):
        loop, large, user = make(part_size=16)
        inner = PusTc(APID, 17, 1, b"", 99, 0x0F, 7).pack()
        txs = user.uplink(APID, inner + b"")
        loop.pump()
        self.assertTrue(all(tx.ok for tx in txs))
        self.assertEqual(len(txs), 2)
        self.assertIn((17, 2), loop.types())  # the reassembled ping was served
        self.assertEqual(large.delivered, 1)

    def test_delivery_to_a_callback(self):
        got = []
        loop, large, user = make(deliver=got.append)
        message = bytes(range(256)) * 5
        user.part_size = 100
        txs = user.uplink(APID, message)
        loop.pump()
        self.assertEqual(len(txs), 13)
        self.assertEqual(got, [message])
        self.assertEqual([tx.tc.subtype for tx in txs], [9] + [10] * 11 + [11])

    def test_out_of_sequence_aborts(self):
        loop, large, user = make(deliver=lambda m: None)
        user.send_part(APID, 0, 5, 1, b"aaa")
        tx = user.send_part(APID, 1, 5, 3, b"ccc")  # part 2 missing
        loop.pump()
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)
        self.assertEqual(user.abortions[-1]["tid"], 5)
        self.assertEqual(user.abortions[-1]["reason"], ABORT_SEQUENCE)
        tx = user.send_part(APID, 2, 6, 2, b"x")  # a last part without a first
        loop.pump()
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)
        self.assertEqual(large.receptions, {})

    def test_receptions_in_progress_are_bounded(self):
        got = []
        loop, large, user = make(deliver=got.append, max_receptions=3)
        firsts = [user.send_part(APID, 0, tid, 1, b"a" * 100) for tid in (1, 2, 3, 4)]
        loop.pump()
        self.assertEqual([tx.ok for tx in firsts], [True, True, True, False])
        self.assertEqual(firsts[3].failure["code"], FAILURE_REFUSED)
        self.assertEqual(sorted(large.receptions), [1, 2, 3])
        self.assertEqual(large.refused, 1)
        tx = user.send_part(APID, 0, 2, 1, b"b")  # a first part again restarts its own
        loop.pump()
        self.assertTrue(tx.ok)
        tx = user.send_part(APID, 2, 1, 2, b"z")  # one ends: room for a new one
        loop.pump()
        self.assertTrue(tx.ok)
        self.assertEqual(got, [b"a" * 100 + b"z"])
        tx = user.send_part(APID, 0, 4, 1, b"c")
        loop.pump()
        self.assertTrue(tx.ok)
        self.assertEqual(sorted(large.receptions), [2, 3, 4])

    def test_reception_timeout(self):
        loop, large, user = make(timeout=5.0, deliver=lambda m: None)
        user.send_part(APID, 0, 8, 1, b"first")
        loop.pump()
        loop.clock.advance(4.0)
        loop.app.tick()
        self.assertIn(8, large.receptions)
        loop.clock.advance(2.0)
        loop.app.tick()
        loop.pump()
        self.assertEqual(large.receptions, {})
        self.assertEqual(
            user.abortions[-1],
            {"tid": 8, "reason": ABORT_TIMEOUT, "reason_name": "reception timeout"},
        )
        tx = user.send_part(APID, 2, 8, 2, b"late")
        loop.pump()
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)

    def test_too_large_and_commanded_abort(self):
        loop, large, user = make(max_size=10, deliver=lambda m: None)
        user.send_part(APID, 0, 1, 1, b"123456")
        tx = user.send_part(APID, 1, 1, 2, b"789012")
        loop.pump()
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)
        self.assertEqual(user.abortions[-1]["reason"], ABORT_TOO_LARGE)
        user.send_part(APID, 0, 2, 1, b"12")
        loop.pump()
        self.assertTrue(large.abort_uplink(2))
        self.assertFalse(large.abort_uplink(2))
        loop.pump()
        self.assertEqual(user.abortions[-1]["reason"], ABORT_COMMANDED)

    def test_undeliverable(self):
        def refuse(message):
            raise ValueError("no room")

        loop, large, user = make(deliver=refuse)
        txs = user.uplink(APID, b"abcdef")
        loop.pump()
        self.assertEqual(txs[-1].failure["code"], FAILURE_REFUSED)
        self.assertEqual(user.abortions[-1]["reason"], 4)


class TestDownlink(unittest.TestCase):
    def test_parts_paced_per_cycle_and_put_back_together(self):
        loop, large, user = make(part_size=100, parts_per_cycle=2)
        message = bytes(range(256)) * 2
        tid = large.downlink(message)
        loop.app.tick()
        loop.pump()
        self.assertEqual(loop.types(), [(13, 1), (13, 2)])
        for _ in range(3):
            loop.app.tick()
        loop.pump()
        self.assertEqual(loop.types()[-1], (13, 3))
        self.assertEqual(user.messages, [(tid, message)])

    def test_a_large_report(self):
        loop, large, user = make(part_size=64, parts_per_cycle=None)
        big = bytes(1000)
        large.downlink_report(17, 2, big)
        loop.pump()
        ((tid, raw),) = user.messages
        tm = PusTm.unpack(raw)
        self.assertEqual((tm.service, tm.subtype, tm.data), (17, 2, big))

    def test_abort_and_ground_timeout(self):
        loop, large, user = make(part_size=10, parts_per_cycle=1)
        user.timeout = 3.0
        tid = large.downlink(bytes(50))
        loop.app.tick()
        loop.pump()
        self.assertTrue(large.abort_downlink(tid))
        self.assertFalse(large.abort_downlink(tid))
        loop.app.tick()
        loop.pump()
        self.assertEqual(len(loop.tm), 1)
        self.assertEqual(user.expire(loop.clock.now() + 1.0), 0)
        self.assertEqual(user.expire(loop.clock.now() + 5.0), 1)
        self.assertEqual((user.partial, user.aborted, user.messages), ({}, 1, []))

    def test_ground_drops_a_downlink_out_of_sequence(self):
        loop, large, user = make(part_size=10, parts_per_cycle=None)
        lost = []
        loop.app.out = lambda raw: (
            lost.append(raw) if raw[8] == 2 and not lost else loop.down.append(raw)
        )
        large.downlink(bytes(35))
        loop.pump()
        self.assertEqual(user.messages, [])
        self.assertEqual(user.aborted, 1)


if __name__ == "__main__":
    unittest.main()
