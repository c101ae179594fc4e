"""SpaceCAN fragmentation and reassembly: wire format, and faults never blocking later packets."""

import unittest

from obsw.spacecan.fragment import (
    MAX_PACKET_SIZE,
    PacketTooLongError,
    Reassembler,
    frame_count,
    split,
)


def h(s):
    return bytes.fromhex(s)


K = 0x281


class TestSplit(unittest.TestCase):
    def test_trace_ping(self):
        self.assertEqual(split(h("1101")), [h("00001101")])

    def test_trace_two_frames(self):
        # 20,1 N=4 ids 1..4, captured as 0100140104010203 + 010104
        self.assertEqual(split(h("14010401020304")), [h("0100140104010203"), h("010104")])

    def test_empty_packet_is_one_frame(self):
        self.assertEqual(split(b""), [h("0000")])

    def test_sizes(self):
        self.assertEqual(len(split(bytes(6))), 1)
        self.assertEqual(len(split(bytes(7))), 2)
        frames = split(bytes(range(256)) * 6)
        self.assertEqual(len(frames), 256)
        self.assertEqual(frames[-1][:2], h("ffff"))
        self.assertEqual(frame_count(0), 1)
        self.assertEqual(frame_count(13), 3)

    def test_too_long(self):
        self.assertEqual(len(split(bytes(MAX_PACKET_SIZE))), 256)
        with self.assertRaises(PacketTooLongError) as cm:
            split(bytes(MAX_PACKET_SIZE + 1))
        self.assertEqual(cm.exception.length, 1537)


class TestReassembly(unittest.TestCase):
    def feed(self, r, frames, now=0.0, key=K):
        out = []
        for f in frames:
            p = r.push(key, f, now)
            if p is not None:
                out.append(p)
        return out

    def test_round_trip(self):
        r = Reassembler()
        for n in (0, 1, 6, 7, 12, 13, 100, MAX_PACKET_SIZE):
            data = bytes((i * 7) & 0xFF for i in range(n))
            self.assertEqual(self.feed(r, split(data)), [data])
        self.assertEqual(r.counters["packets"], 8)
        self.assertEqual(r.dropped(), 0)
        self.assertEqual(r.pending(), 0)

    def test_stray_fragment_does_not_block(self):
        # the trace: a stray "index 1 of 3" then pings; spacecan swallowed the pings
        r = Reassembler()
        self.assertEqual(self.feed(r, [h("0201dead")]), [])
        self.assertEqual(self.feed(r, [h("00001101")]), [h("1101")])
        self.assertEqual(self.feed(r, [h("00001101")]), [h("1101")])
        self.assertEqual(r.counters["stray"], 1)

    def test_lost_fragment_then_new_packet(self):
        r = Reassembler()
        frames = split(bytes(20))  # 4 frames
        self.assertEqual(self.feed(r, frames[:2]), [])
        # the rest is lost; a new packet starts with index 0 and must come through
        self.assertEqual(self.feed(r, split(h("1101"))), [h("1101")])
        self.assertEqual(r.counters["restarts"], 1)

    def test_gap_drops_partial(self):
        r = Reassembler()
        f = split(bytes(range(20)))
        self.assertEqual(self.feed(r, [f[0], f[2], f[3]]), [])
        self.assertEqual(r.counters["gaps"], 1)
        self.assertEqual(r.counters["stray"], 1)
        self.assertEqual(self.feed(r, f), [bytes(range(20))])

    def test_duplicates_dropped(self):
        r = Reassembler()
        f = split(bytes(range(14)))
        self.assertEqual(self.feed(r, [f[0], f[1], f[1], f[2]]), [bytes(range(14))])
        self.assertEqual(r.counters["duplicates"], 1)

    def test_inconsistent_total(self):
        r = Reassembler()
        f = split(bytes(range(14)))  # total 3
        bad = bytes((5, 1)) + f[1][2:]
        self.assertEqual(self.feed(r, [f[0], bad, f[1], f[2]]), [bytes(range(14))])
        self.assertEqual(r.counters["inconsistent"], 1)

    def test_bad_index_and_short(self):
        r = Reassembler()
        self.assertEqual(self.feed(r, [h("0105aa"), h("00"), b""]), [])
        self.assertEqual(r.counters["bad_index"], 1)
        self.assertEqual(r.counters["short"], 2)

    def test_timeout(self):
        r = Reassembler(timeout=0.1)
        f = split(bytes(14))
        r.push(K, f[0], 0.0)
        self.assertEqual(r.next_deadline(), 0.1)
        self.assertEqual(r.expire(0.05), 0)
        self.assertEqual(r.expire(0.2), 1)
        self.assertIsNone(r.next_deadline())
        self.assertIsNone(r.push(K, f[1], 0.2))
        self.assertEqual(r.counters["timeouts"], 1)
        self.assertEqual(r.counters["stray"], 1)

    def test_timeout_checked_on_arrival(self):
        r = Reassembler(timeout=0.1)
        f = split(bytes(14))
        r.push(K, f[0], 0.0)
        self.assertIsNone(r.push(K, f[1], 0.5))
        self.assertEqual(r.counters["timeouts"], 1)

    def test_keys_independent(self):
        r = Reassembler()
        a = split(bytes(range(14)))
        b = split(bytes(range(100, 114)))
        out = []
        for i in range(3):
            for key, f in ((1, a), (2, b)):
                p = r.push(key, f[i], 0.0)
                if p is not None:
                    out.append(p)
        self.assertEqual(out, [bytes(range(14)), bytes(range(100, 114))])
