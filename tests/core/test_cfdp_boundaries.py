"""CFDP edges: the retransmission list's merge, the large file flag at 4 GiB, NAKs clipped to
what was sent, a NAKed gap sent again exactly, a prompted NAK that covers the tail gap, and
Prompts a receiver must ignore."""

import unittest

from cfdp_sim import Link, directive, make_pair, payload
from obsw.cfdp.defs import (
    ACKNOWLEDGED,
    CANCEL_REQUEST_RECEIVED,
    KEEP_ALIVE_LIMIT_REACHED,
    PROMPT_KEEP_ALIVE,
    PROMPT_NAK,
    UNACKNOWLEDGED,
)
from obsw.cfdp.filestore import MemoryFilestore
from obsw.cfdp.pdu.keepalive import KeepAlivePdu
from obsw.cfdp.pdu.nak import NakPdu
from obsw.cfdp.pdu.prompt import PromptPdu
from obsw.cfdp.receiver import Receiver, _merge_closest
from obsw.cfdp.sender import SENDING, add_interval

DATA = payload(2000)
DIR_EOF = 0x04
DIR_NAK = 0x08
DIR_KEEP_ALIVE = 0x0C


def file_offset(pdu):
    """The offset of a raw file data PDU (small file, no segment metadata), or None."""
    if not pdu[0] & 0x10:
        return None
    at = 4 + 2 * (((pdu[3] >> 4) & 7) + 1) + (pdu[3] & 7) + 1  # past the fixed header
    return int.from_bytes(pdu[at : at + 4], "big")


def file_data_length(pdu):
    """The octets of file data a raw file data PDU carries (small file, no segment metadata)."""
    crc = 2 if pdu[0] & 0x02 else 0
    return int.from_bytes(pdu[1:3], "big") - 4 - crc


class SizedFilestore(MemoryFilestore):
    """A filestore whose one file reports ``size`` octets (none of which is ever read here)."""

    def __init__(self, size):
        super().__init__({"big.bin": b""})
        self._size = size

    def size(self, name):
        return self._size


class TestAddInterval(unittest.TestCase):
    def test_overlapping_from_above_keeps_the_lower_start(self):
        lst = [[10, 20]]
        add_interval(lst, 15, 30)
        self.assertEqual(lst, [[10, 30]])

    def test_touching_intervals_merge(self):
        lst = [[10, 20], [30, 40]]
        add_interval(lst, 20, 30)
        self.assertEqual(lst, [[10, 40]])

    def test_disjoint_intervals_stay_apart_in_order(self):
        lst = [[10, 20], [50, 60]]
        add_interval(lst, 30, 40)
        self.assertEqual(lst, [[10, 20], [30, 40], [50, 60]])
        add_interval(lst, 0, 5)
        add_interval(lst, 70, 80)
        self.assertEqual(lst, [[0, 5], [10, 20], [30, 40], [50, 60], [70, 80]])

    def test_one_interval_covering_several(self):
        lst = [[10, 20], [30, 40], [50, 60]]
        add_interval(lst, 5, 55)
        self.assertEqual(lst, [[5, 60]])


class TestLargeFileFlag(unittest.TestCase):
    def large(self, size):
        a, _ = make_pair()
        a.fs = SizedFilestore(size)
        return a.find(a.put(2, "big.bin", "big.bin")).header.large

    def test_below_4_gib_is_small(self):
        self.assertFalse(self.large(0))
        self.assertFalse(self.large(2000))
        self.assertFalse(self.large((1 << 32) - 1))

    def test_4_gib_and_above_is_large(self):
        self.assertTrue(self.large(1 << 32))
        self.assertTrue(self.large((1 << 33) + 1))


class TestNakClippedToProgress(unittest.TestCase):
    def test_a_nak_beyond_what_was_sent_asks_only_for_what_was_sent(self):
        a, _ = make_pair(files_a={"src.bin": DATA}, mode=ACKNOWLEDGED)
        tid = a.put(2, "src.bin", "dst.bin")
        a.transmit(0, 3)  # metadata and the first two segments
        tx = a.find(tid)
        self.assertEqual((tx.state_, tx.progress), (SENDING, 128))
        tx.on_pdu(NakPdu(tx.directive_header(), 0, len(DATA), [(0, len(DATA))]), 1)
        self.assertEqual(tx.resend, [[0, 128]])


class TestResendOfAGap(unittest.TestCase):
    def test_a_nakked_gap_is_sent_again_to_its_last_octet_and_no_further(self):
        a, _ = make_pair(files_a={"src.bin": DATA}, mode=ACKNOWLEDGED)
        tid = a.put(2, "src.bin", "dst.bin")
        a.transmit(0, 3)  # metadata and the first two segments (128 octets)
        tx = a.find(tid)
        tx.on_pdu(NakPdu(tx.directive_header(), 0, 128, [(100, 110)]), 1)
        self.assertEqual(tx.resend, [[100, 110]])
        (pdu,) = [pdu for _dest, pdu in a.transmit(2, 1)]
        self.assertEqual((file_offset(pdu), file_data_length(pdu)), (100, 10))
        self.assertEqual(tx.resend, [])


def deliver(src, dst, now, keep=lambda pdu: True):
    """Every PDU ``src`` has to send, those ``keep`` accepts handed to ``dst``; the raw PDUs."""
    sent = []
    while True:
        out = [pdu for _dest, pdu in src.transmit(now, 32)]
        if not out:
            return sent
        for pdu in out:
            sent.append(pdu)
            if keep(pdu):
                dst.receive(pdu, now)


class TestPrompts(unittest.TestCase):
    def test_a_prompted_nak_names_the_gap_at_the_end_of_the_file(self):
        a, b = make_pair(files_a={"src.bin": DATA}, mode=ACKNOWLEDGED)
        tid = a.put(2, "src.bin", "dst.bin")
        tail = 1280
        sent = deliver(a, b, 0, lambda pdu: (file_offset(pdu) or 0) < tail)
        self.assertIn(DIR_EOF, [directive(p) for p in sent])
        deliver(b, a, 0, lambda pdu: False)  # the EOF ACK and the NAK at EOF, lost
        self.assertTrue(a.prompt(tid, PROMPT_NAK, 1))
        deliver(a, b, 1)
        naks = [
            a.receive(p, 1) for p in deliver(b, a, 1, lambda p: False) if directive(p) == DIR_NAK
        ]
        self.assertEqual(len(naks), 1)
        self.assertEqual(naks[0].segments, [(tail, len(DATA))])

    def test_an_unacknowledged_receiver_ignores_prompts(self):
        a, b = make_pair(files_a={"src.bin": DATA}, mode=UNACKNOWLEDGED)
        tid = a.put(2, "src.bin", "dst.bin")
        first = [pdu for _dest, pdu in a.transmit(0, 2)]  # metadata, first segment
        for pdu in first:
            b.receive(pdu, 0)
        header = a.find(tid).directive_header()
        for kind in (PROMPT_KEEP_ALIVE, PROMPT_NAK):
            b.receive(PromptPdu(header, kind).pack(), 1)
        self.assertEqual([pdu for _dest, pdu in b.transmit(1, 32)], [])


class Gaps:
    """Just the gap list of a receiver, for its gap bookkeeping."""

    def __init__(self, gaps):
        self.gaps = gaps


class TestGaps(unittest.TestCase):
    def test_merge_the_two_gaps_with_the_fewest_octets_between(self):
        gaps = [[0, 90, None], [100, 200, None], [205, 206, None]]  # 10 and 5 octets between
        _merge_closest(gaps)
        self.assertEqual(gaps, [[0, 90, None], [100, 206, None]])
        gaps = [[0, 10, None], [12, 200, None], [205, 206, None]]  # 2 and 5 octets between
        _merge_closest(gaps)
        self.assertEqual(gaps, [[0, 200, None], [205, 206, None]])

    def test_data_just_after_a_gap_fills_nothing(self):
        r = Gaps([[0, 64, None]])
        self.assertFalse(Receiver._fill(r, 64, 128))
        self.assertEqual(r.gaps, [[0, 64, None]])

    def test_data_just_before_a_gap_fills_nothing(self):
        r = Gaps([[64, 128, None]])
        self.assertFalse(Receiver._fill(r, 0, 64))
        self.assertEqual(r.gaps, [[64, 128, None]])

    def test_data_overlapping_a_gap_edge_by_one_octet(self):
        r = Gaps([[64, 128, None]])
        self.assertTrue(Receiver._fill(r, 0, 65))
        self.assertEqual(r.gaps, [[65, 128, None]])
        self.assertTrue(Receiver._fill(r, 127, 200))
        self.assertEqual(r.gaps, [[65, 127, None]])


class TestNakPdus(unittest.TestCase):
    def test_naks_split_over_pdus_each_scoped_from_its_first_segment(self):
        a, b = make_pair(files_a={"src.bin": DATA}, mode=ACKNOWLEDGED, max_pdu=40)
        tid = a.put(2, "src.bin", "dst.bin")
        deliver(a, b, 0, lambda pdu: directive(pdu) is not None and directive(pdu) != DIR_EOF)
        rx = b.find(tid)
        segments = [(100 * i, 100 * i + 10) for i in range(1, 8)]
        before = b.stats["naks_sent"]
        rx._send_naks(segments, 0, 1000)
        naks = [a.receive(p, 0) for p in deliver(b, a, 0, lambda p: False)]
        naks = [n for n in naks if n is not None and n.CODE == DIR_NAK]
        self.assertTrue(len(naks) > 1)
        self.assertEqual(b.stats["naks_sent"] - before, len(naks))
        self.assertEqual([s for n in naks for s in n.segments], segments)
        self.assertEqual(naks[0].start, 0)
        for n in naks[1:]:
            self.assertEqual(n.start, n.segments[0][0])
        self.assertEqual(naks[-1].end, 1000)


class TestUnacknowledgedLoss(unittest.TestCase):
    def test_a_lost_segment_brings_no_nak_in_unacknowledged_mode(self):
        a, b = make_pair(files_a={"src.bin": DATA}, mode=UNACKNOWLEDGED)
        a.put(2, "src.bin", "dst.bin")
        deliver(a, b, 0, lambda pdu: file_offset(pdu) != 640)
        self.assertEqual(b.stats["naks_sent"], 0)
        sent = [pdu for _dest, pdu in b.transmit(0, 32)]
        self.assertEqual([directive(p) for p in sent if directive(p) == DIR_NAK], [])


class TestDestinationDirectory(unittest.TestCase):
    def test_a_file_sent_to_a_directory_lands_under_its_own_name(self):
        a, b = make_pair(files_a={"sub/src.bin": DATA[:100]}, mode=ACKNOWLEDGED)
        b.fs.mkdir("inbox")
        a.put(2, "sub/src.bin", "inbox/")
        link = Link(a, b)
        link.run()
        self.assertEqual(b.fs.read_bytes("inbox/src.bin"), DATA[:100])


class TestSenderLimits(unittest.TestCase):
    def sender_at(self, progress, **kw):
        a, _ = make_pair(files_a={"src.bin": DATA}, mode=ACKNOWLEDGED, **kw)
        tid = a.put(2, "src.bin", "dst.bin")
        a.transmit(0, 1 + progress // 64)  # metadata and the segments up to ``progress``
        tx = a.find(tid)
        self.assertEqual(tx.progress, progress)
        return a, tx

    def test_keep_alive_exactly_the_limit_behind(self):
        a, tx = self.sender_at(192, keep_alive_limit=100)
        tx.on_pdu(KeepAlivePdu(tx.directive_header(), 92), 1)
        self.assertEqual([i for i in a.pop_indications() if i.kind == "fault"], [])
        self.assertFalse(tx.done)

    def test_keep_alive_one_more_behind(self):
        a, tx = self.sender_at(192, keep_alive_limit=100)
        tx.on_pdu(KeepAlivePdu(tx.directive_header(), 91), 1)
        faults = [i.info["condition"] for i in a.pop_indications() if i.kind == "fault"]
        self.assertEqual(faults, [KEEP_ALIVE_LIMIT_REACHED])

    def test_an_unacknowledged_cancel_reports_the_data_incomplete(self):
        a, b = make_pair(files_a={"src.bin": DATA}, mode=UNACKNOWLEDGED)
        tid = a.put(2, "src.bin", "dst.bin")
        a.transmit(0, 3)
        a.cancel(tid, 1)
        deliver(a, b, 1)
        done = [i for i in a.pop_indications() if i.kind == "finished"]
        self.assertEqual(len(done), 1)
        self.assertEqual(done[0].info["condition"], CANCEL_REQUEST_RECEIVED)
        self.assertEqual(done[0].info["delivery"], 1)  # data incomplete


if __name__ == "__main__":
    unittest.main()
