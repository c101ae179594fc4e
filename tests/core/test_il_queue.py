"""Queue: FreeRTOS xQueue semantics, full policies and blocking on a simulated clock."""

import unittest

from obsw.il.clock import SimClock
from obsw.il.queue import (
    BLOCK,
    DROP_NEWEST,
    EMPTY,
    FOREVER,
    OVERWRITE_OLDEST,
    Queue,
    policy_name,
)


class TestBasics(unittest.TestCase):
    def test_fifo_and_counts(self):
        q = Queue(3)
        self.assertEqual((q.messages_waiting(), q.spaces_available()), (0, 3))
        self.assertTrue(q.send("a"))
        self.assertTrue(q.send("b"))
        self.assertEqual((q.messages_waiting(), q.spaces_available()), (2, 1))
        self.assertEqual(q.receive(), "a")
        self.assertTrue(q.send("c"))
        self.assertTrue(q.send("d"))  # wraps around the ring
        self.assertTrue(q.is_full())
        self.assertEqual([q.receive() for _ in range(3)], ["b", "c", "d"])
        self.assertTrue(q.is_empty())

    def test_full_and_empty_are_results(self):
        q = Queue(1)
        self.assertIs(q.receive(), EMPTY)
        self.assertIs(q.peek(), EMPTY)
        self.assertTrue(q.send(None))
        self.assertFalse(q.send(2))
        self.assertFalse(q.send_to_front(2))
        self.assertIsNone(q.receive())  # None is a valid item, distinct from EMPTY
        self.assertFalse(bool(EMPTY))

    def test_send_to_front(self):
        q = Queue(4)
        q.send(1)
        q.send(2)
        q.send_to_front(0)
        q.send_to_front(-1)
        self.assertEqual([q.receive() for _ in range(4)], [-1, 0, 1, 2])

    def test_peek_does_not_remove(self):
        q = Queue(2)
        q.send("x")
        self.assertEqual(q.peek(), "x")
        self.assertEqual(q.messages_waiting(), 1)
        self.assertEqual(q.receive(), "x")

    def test_overwrite_mailbox(self):
        box = Queue(1)
        self.assertTrue(box.overwrite(1))
        self.assertTrue(box.overwrite(2))
        self.assertEqual(box.peek(), 2)
        self.assertEqual(box.messages_waiting(), 1)
        with self.assertRaises(ValueError):
            Queue(2).overwrite(1)

    def test_copy_in(self):
        q = Queue(3)
        buf = bytearray(b"ab")
        items = [1, 2]
        q.send(buf)
        q.send(items)
        q.send(memoryview(b"xyz")[1:])
        buf[0] = 0
        items.append(3)
        self.assertEqual(q.receive(), bytearray(b"ab"))
        self.assertEqual(q.receive(), [1, 2])
        self.assertEqual(q.receive(), b"yz")

    def test_no_copy_option(self):
        q = Queue(1, copy=False)
        items = [1]
        q.send(items)
        self.assertIs(q.receive(), items)

    def test_reset(self):
        q = Queue(2)
        q.send(1)
        q.send(2)
        q.reset()
        self.assertEqual(q.messages_waiting(), 0)
        self.assertTrue(q.send(3))
        self.assertEqual(q.receive(), 3)

    def test_bad_construction(self):
        with self.assertRaises(ValueError):
            Queue(0)
        with self.assertRaises(ValueError):
            Queue(2, policy=7)

    def test_repr_and_policy_names(self):
        q = Queue(2, DROP_NEWEST, name="tm")
        self.assertIn("tm", repr(q))
        self.assertEqual(policy_name(OVERWRITE_OLDEST), "overwrite-oldest")
        self.assertEqual(len(q), 0)


class TestPolicies(unittest.TestCase):
    def test_drop_newest_counts(self):
        q = Queue(2, DROP_NEWEST)
        self.assertTrue(q.put(1))
        self.assertTrue(q.put(2))
        self.assertFalse(q.put(3))
        self.assertFalse(q.put(4))
        self.assertEqual(q.dropped, 2)
        self.assertEqual([q.receive(), q.receive()], [1, 2])

    def test_overwrite_oldest_counts(self):
        q = Queue(2, OVERWRITE_OLDEST)
        for i in range(5):
            self.assertTrue(q.put(i))
        self.assertEqual(q.dropped, 3)
        self.assertEqual([q.receive(), q.receive()], [3, 4])

    def test_block_policy_times_out_then_counts(self):
        clock = SimClock()
        q = Queue(1, BLOCK, 0.5, clock=clock)
        q.put("a")
        self.assertFalse(q.put("b"))
        self.assertEqual(clock.now(), 0.5)
        self.assertEqual(q.dropped, 1)

    def test_block_policy_waits_for_consumer(self):
        clock = SimClock()
        q = Queue(1, BLOCK, 1.0, clock=clock)
        q.put("a")
        got = []
        clock.call_at(0.25, lambda: got.append(q.receive()))
        self.assertTrue(q.put("b"))
        self.assertEqual(clock.now(), 0.25)
        self.assertEqual(got, ["a"])
        self.assertEqual(q.dropped, 0)


class TestBlocking(unittest.TestCase):
    def setUp(self):
        self.clock = SimClock()
        self.q = Queue(2, clock=self.clock)

    def test_receive_times_out(self):
        self.assertIs(self.q.receive(0.3), EMPTY)
        self.assertAlmostEqual(self.clock.now(), 0.3)

    def test_receive_wakes_when_item_arrives(self):
        self.clock.call_at(0.1, lambda: self.q.send("late"))
        self.assertEqual(self.q.receive(1.0), "late")
        self.assertAlmostEqual(self.clock.now(), 0.1)

    def test_receive_forever(self):
        self.clock.call_at(100.0, lambda: self.q.send("x"))
        self.assertEqual(self.q.receive(FOREVER), "x")
        self.assertEqual(self.clock.now(), 100.0)

    def test_peek_waits(self):
        self.clock.call_at(0.2, lambda: self.q.send(7))
        self.assertEqual(self.q.peek(0.5), 7)
        self.assertEqual(self.q.receive(), 7)

    def test_send_waits_for_space(self):
        self.q.send(1)
        self.q.send(2)
        self.clock.call_at(0.4, self.q.receive)
        self.assertTrue(self.q.send(3, 1.0))
        self.assertAlmostEqual(self.clock.now(), 0.4)
        self.assertEqual([self.q.receive(), self.q.receive()], [2, 3])

    def test_send_to_front_times_out(self):
        self.q.send(1)
        self.q.send(2)
        self.assertFalse(self.q.send_to_front(0, 0.2))
        self.assertAlmostEqual(self.clock.now(), 0.2)

    def test_unrelated_timer_does_not_satisfy_wait(self):
        self.clock.call_at(0.1, lambda: None)
        self.clock.call_at(0.3, lambda: self.q.send("y"))
        self.assertEqual(self.q.receive(0.5), "y")
        self.assertAlmostEqual(self.clock.now(), 0.3)


class TestSimClock(unittest.TestCase):
    def test_timers_run_in_order(self):
        clock = SimClock()
        seen = []
        clock.call_at(2.0, lambda: seen.append(("b", clock.now())))
        clock.call_at(1.0, lambda: seen.append(("a", clock.now())))
        e = clock.call_later(1.5, lambda: seen.append("never"))
        clock.cancel(e)
        clock.advance(3.0)
        self.assertEqual(seen, [("a", 1.0), ("b", 2.0)])
        self.assertEqual(clock.now(), 3.0)
        self.assertEqual(clock.pending(), 0)


if __name__ == "__main__":
    unittest.main()
