"""The deduplicator of hot-redundant links: the second copy of a frame from the other link is
dropped, within its window and its depth, however far one link lags behind the other."""

import unittest

from obsw.frames.dedup import Deduplicator


class TestDedup(unittest.TestCase):
    def test_the_copy_from_the_other_link_is_dropped_once(self):
        d = Deduplicator(2.0)
        self.assertFalse(d.duplicate(b"a", 0, 0.0))
        self.assertFalse(d.duplicate(b"a", 0, 0.1))  # the same link: a retransmission
        self.assertTrue(d.duplicate(b"a", 1, 0.2))
        self.assertTrue(d.duplicate(b"a", 1, 0.3))  # pairs the second copy from link 0
        self.assertFalse(d.duplicate(b"a", 1, 0.4))  # nothing left to pair with
        self.assertEqual(d.dropped, 2)

    def test_outside_the_window_a_frame_is_new(self):
        d = Deduplicator(2.0)
        self.assertFalse(d.duplicate(b"a", 0, 0.0))
        self.assertFalse(d.duplicate(b"a", 1, 2.5))

    def test_a_link_lagging_by_many_frames_within_the_depth(self):
        d = Deduplicator(10.0, depth=1000)
        frames = [bytes((i >> 8, i & 0xFF)) for i in range(600)]
        for f in frames:
            self.assertFalse(d.duplicate(f, 0, 1.0))
        for f in frames:
            self.assertTrue(d.duplicate(f, 1, 2.0))
        self.assertEqual(d.dropped, 600)

    def test_beyond_the_depth_the_oldest_is_forgotten(self):
        d = Deduplicator(10.0, depth=4)
        for i in range(6):
            d.duplicate(bytes((i,)), 0, 0.0)
        self.assertFalse(d.duplicate(bytes((0,)), 1, 0.0))
        self.assertTrue(d.duplicate(bytes((5,)), 1, 0.0))


if __name__ == "__main__":
    unittest.main()
