"""CCSDS 133.0-B-2 space packets: header fields, counters, idle packets and the stream parser."""

import unittest

from obsw import spp

# A TC with secondary header, APID 0x123, unsegmented, count 0x1A2B, 3 octets of data:
#   packet ID  = version 000 | type 1 | sec hdr 1 | APID 001 0010 0011 -> 0001 1001 0010 0011
#   seq ctrl   = flags 11 | count 01 1010 0010 1011                   -> 1101 1010 0010 1011
#   length     = 3 octets - 1                                          -> 0x0002
TC_VECTOR = bytes.fromhex("1923da2b0002") + b"\x01\x02\x03"
# A TM without secondary header, APID 0x7FE, first segment, count 0, one octet of data:
#   0000 0111 1111 1110 | 0100 0000 0000 0000 | 0x0000
TM_VECTOR = bytes.fromhex("07fe40000000") + b"\xee"


class TestPrimaryHeader(unittest.TestCase):
    def test_tc_vector_fields(self):
        h = spp.PrimaryHeader.unpack(TC_VECTOR)
        self.assertEqual(h.version, 0)
        self.assertEqual(h.packet_type, spp.TYPE_TC)
        self.assertTrue(h.sec_header_flag)
        self.assertEqual(h.apid, 0x123)
        self.assertEqual(h.seq_flags, spp.SEQ_UNSEGMENTED)
        self.assertEqual(h.seq_count, 0x1A2B)
        self.assertEqual(h.data_length, 2)
        self.assertEqual(h.packet_length, 9)
        self.assertEqual(h.packet_id, 0x1923)
        self.assertEqual(h.sequence_control, 0xDA2B)

    def test_pack_matches_vector(self):
        h = spp.PrimaryHeader(spp.TYPE_TC, True, 0x123, spp.SEQ_UNSEGMENTED, 0x1A2B, 2)
        self.assertEqual(h.pack(), TC_VECTOR[:6])
        self.assertEqual(spp.PrimaryHeader.unpack(h.pack()), h)

    def test_header_reads_any_version(self):
        h = spp.PrimaryHeader.unpack(b"\xe0\x00\xc0\x00\x00\x00")
        self.assertEqual(h.version, 7)

    def test_too_short(self):
        with self.assertRaises(spp.BytesTooShortError) as cm:
            spp.PrimaryHeader.unpack(b"\x00\x01\x02")
        self.assertEqual(cm.exception.needed, 6)
        self.assertEqual(cm.exception.got, 3)

    def test_pack_rejects_out_of_range(self):
        for kw in (
            {"apid": 0x800},
            {"seq_count": 0x4000},
            {"seq_flags": 4},
            {"data_length": 0x10000},
            {"apid": -1},
        ):
            h = spp.PrimaryHeader(spp.TYPE_TM, False, **kw)
            with self.assertRaises(spp.FieldRangeError):
                h.pack()


class TestSpacePacket(unittest.TestCase):
    def test_unpack_tc_vector(self):
        p = spp.SpacePacket.unpack(TC_VECTOR)
        self.assertEqual(p.packet_type, spp.TYPE_TC)
        self.assertEqual(p.apid, 0x123)
        self.assertEqual(p.sec_header_flag, 1)
        self.assertEqual(p.seq_count, 0x1A2B)
        self.assertEqual(p.data, b"\x01\x02\x03")
        self.assertEqual(p.data_length, 2)
        self.assertEqual(len(p), 9)

    def test_unpack_tm_vector(self):
        p = spp.SpacePacket.unpack(TM_VECTOR)
        self.assertEqual(p.packet_type, spp.TYPE_TM)
        self.assertEqual(p.apid, 0x7FE)
        self.assertEqual(p.seq_flags, spp.SEQ_FIRST)
        self.assertEqual(p.data, b"\xee")
        self.assertFalse(p.sec_header_flag)
        self.assertFalse(p.is_idle)

    def test_pack_matches_vectors(self):
        tc = spp.SpacePacket(spp.TYPE_TC, 0x123, b"\x01\x02\x03", True, 3, 0x1A2B)
        self.assertEqual(tc.pack(), TC_VECTOR)
        tm = spp.SpacePacket(spp.TYPE_TM, 0x7FE, b"\xee", False, spp.SEQ_FIRST, 0)
        self.assertEqual(tm.pack(), TM_VECTOR)

    def test_unpack_from_offset_and_trailing(self):
        buf = b"\xaa" + TC_VECTOR + TM_VECTOR
        p, end = spp.SpacePacket.unpack_from(buf, 1)
        self.assertEqual(p.apid, 0x123)
        self.assertEqual(end, 1 + len(TC_VECTOR))
        q, end2 = spp.SpacePacket.unpack_from(buf, end)
        self.assertEqual(q.apid, 0x7FE)
        self.assertEqual(end2, len(buf))

    def test_truncated_packet(self):
        with self.assertRaises(spp.BytesTooShortError) as cm:
            spp.SpacePacket.unpack(TC_VECTOR[:-1])
        self.assertEqual(cm.exception.needed, 9)
        self.assertEqual(cm.exception.got, 8)

    def test_wrong_version(self):
        bad = bytes([TC_VECTOR[0] | 0x20]) + TC_VECTOR[1:]
        with self.assertRaises(spp.PacketVersionError) as cm:
            spp.SpacePacket.unpack(bad)
        self.assertEqual(cm.exception.version, 1)
        self.assertIsInstance(cm.exception, ValueError)

    def test_empty_data_field_rejected(self):
        with self.assertRaises(spp.FieldRangeError):
            spp.SpacePacket(spp.TYPE_TM, 1, b"").pack()

    def test_largest_packet(self):
        p = spp.SpacePacket(spp.TYPE_TM, 1, bytes(65536))
        raw = p.pack()
        self.assertEqual(len(raw), spp.MAX_PACKET_SIZE)
        self.assertEqual(raw[4:6], b"\xff\xff")
        with self.assertRaises(spp.FieldRangeError):
            spp.SpacePacket(spp.TYPE_TM, 1, bytes(65537)).pack()


class TestIdleAndCounters(unittest.TestCase):
    def test_idle_packet(self):
        p = spp.idle_packet(10, seq_count=5, pattern=b"\x55\xaa")
        raw = p.pack()
        # APID all ones, no secondary header, unsegmented, count 5, 4 data octets
        self.assertEqual(raw, bytes.fromhex("07ffc0050003") + b"\x55\xaa\x55\xaa")
        self.assertTrue(spp.SpacePacket.unpack(raw).is_idle)
        with self.assertRaises(spp.FieldRangeError):
            spp.idle_packet(6)

    def test_counter_per_apid_and_wrap(self):
        c = spp.SequenceCounter()
        self.assertEqual(c.next(1), 0)
        self.assertEqual(c.next(1), 1)
        self.assertEqual(c.next(2), 0)
        c.set(1, 0x3FFF)
        self.assertEqual(c.next(1), 0x3FFF)
        self.assertEqual(c.next(1), 0)
        self.assertEqual(c.peek(2), 1)
        self.assertEqual(c.counts(), {1: 1, 2: 1})  # what a context keeps
        c.reset(2)
        self.assertEqual(c.peek(2), 0)
        with self.assertRaises(spp.FieldRangeError):
            c.set(1, 0x4000)

    def test_monitor_counts_gaps_across_wrap(self):
        m = spp.SequenceMonitor()
        self.assertIsNone(m.observe(5, 0x3FFE))
        self.assertEqual(m.observe(5, 0x3FFF), 0)
        self.assertEqual(m.observe(5, 2), 2)  # 0 and 1 lost
        self.assertIsNone(m.observe(6, 0))
        self.assertEqual(m.lost, 2)


def _pkt(apid, data, count=0):
    return spp.SpacePacket(spp.TYPE_TM, apid, data, False, 3, count).pack()


class TestPacketStream(unittest.TestCase):
    def test_byte_by_byte(self):
        raw = _pkt(10, b"abc") + _pkt(11, b"defg")
        s = spp.PacketStream()
        got = []
        for i in range(len(raw)):
            pkts, skipped = s.feed(raw[i : i + 1])
            got.extend(pkts)
            self.assertEqual(skipped, 0)
        self.assertEqual(got, [_pkt(10, b"abc"), _pkt(11, b"defg")])
        self.assertEqual(s.pending, 0)
        self.assertEqual(s.packets, 2)

    def test_skips_bad_version_and_reports(self):
        garbage = b"\xe0\xe1\xff"  # version 7 everywhere, then a stray octet
        good = _pkt(10, b"xy")
        s = spp.PacketStream()
        pkts, skipped = s.feed(garbage + good)
        self.assertEqual(pkts, [good])
        self.assertEqual(skipped, 3)
        self.assertEqual(s.skipped, 3)
        self.assertEqual(s.reasons[spp.SKIP_VERSION], 3)

    def test_apid_filter(self):
        s = spp.PacketStream(apids={10})
        pkts, skipped = s.feed(_pkt(12, b"q") + _pkt(10, b"r"))
        self.assertEqual(pkts, [_pkt(10, b"r")])
        self.assertEqual(skipped, 7)
        self.assertIn(spp.SKIP_APID, s.reasons)

    def test_length_limit(self):
        s = spp.PacketStream(max_length=10)
        pkts, skipped = s.feed(_pkt(1, b"\xff" * 5) + _pkt(1, b"ok"))
        self.assertEqual(pkts, [_pkt(1, b"ok")])
        self.assertEqual(skipped, 11)
        self.assertIn(spp.SKIP_LENGTH, s.reasons)
        self.assertEqual(sum(s.reasons.values()), 11)

    def test_validator_rejects_and_resyncs(self):
        good = _pkt(3, b"GOOD")
        s = spp.PacketStream(max_length=64, validate=lambda p: p.endswith(b"GOOD"))
        pkts, skipped = s.feed(_pkt(3, b"\xff\xff\xff") + good)
        self.assertEqual(pkts, [good])
        self.assertEqual(skipped, 9)

    def test_flush_gives_up_incomplete_head(self):
        # garbage that looks like the header of a long packet swallows what follows until flush
        fake = bytes.fromhex("0001c00000ff")
        good = _pkt(2, b"zz")
        s = spp.PacketStream()
        pkts, skipped = s.feed(fake + good)
        self.assertEqual(pkts, [])
        self.assertEqual(s.pending, len(fake) + len(good))
        pkts, skipped = s.flush()
        self.assertEqual(pkts, [good])
        self.assertEqual(skipped, len(fake))
        self.assertEqual(s.pending, 0)

    def test_flush_drops_short_tail(self):
        s = spp.PacketStream()
        s.feed(b"\x00\x01")
        pkts, skipped = s.flush()
        self.assertEqual((pkts, skipped), ([], 2))


if __name__ == "__main__":
    unittest.main()
