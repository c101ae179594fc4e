"""CFDP class 2 NAK procedures pinned where they are easy to get wrong: only new data counts as
progress (CCSDS 727.0-B-5 4.6.4.7: a duplicate never resets the NAK limit), and a gap the
receiver has already asked for (immediate NAK mode) is not asked for again at end of file."""

import unittest

from cfdp_sim import Link, directive, make_pair, payload
from obsw.cfdp.defs import ACKNOWLEDGED, NAK_LIMIT_REACHED, NO_ERROR

DATA = payload(2000)
DIR_NAK = 0x08
DIR_EOF = 0x04


def segment_at(pdu, offset):
    """True for a file data PDU of the pair's transfers (64-octet segments) at ``offset``."""
    return bool(pdu[0] & 0x10) and pdu[-68:-64] == offset.to_bytes(4, "big")


class TestNakBoundaries(unittest.TestCase):
    def test_a_duplicate_is_no_progress(self):
        # the segment at 640 never arrives; an old segment arrives again and again while the
        # receiver NAKs: the NAK limit is still reached
        a, b = make_pair(files_a={"src.bin": DATA}, mode=ACKNOWLEDGED)
        a.put(2, "src.bin", "dst.bin")
        first = []

        def drop(side, pdu):
            if side == 0 and not first and segment_at(pdu, 0):
                first.append(pdu)
            return side == 0 and segment_at(pdu, 640)

        link = Link(a, b, drop=drop)
        link.hook = lambda link: first and b.receive(first[0], link.now)
        link.run(max_time=2000)
        self.assertEqual([i.info["condition"] for i in link.finished(1)], [NAK_LIMIT_REACHED])

    def test_a_gap_asked_for_is_not_asked_again_at_eof(self):
        # immediate NAK mode: the gap at 640 is NAKed as soon as the segment after it arrives;
        # its retransmission is lost too, and the EOF brings no new gap: no NAK at EOF
        a, b = make_pair(files_a={"src.bin": DATA}, mode=ACKNOWLEDGED)
        a.put(2, "src.bin", "dst.bin")
        lost = [2]  # the first transmission and the first retransmission of 640
        naks = []  # (time, EOF seen by then) of each NAK the receiver sends
        eof = []

        def drop(side, pdu):
            if side == 0 and directive(pdu) == DIR_EOF:
                eof.append(link.now)
            if side == 1 and directive(pdu) == DIR_NAK:
                naks.append((link.now, bool(eof)))
            if side == 0 and lost[0] and segment_at(pdu, 640):
                lost[0] -= 1
                return True
            return False

        link = Link(a, b, drop=drop)
        link.run()
        self.assertEqual([i.info["condition"] for i in link.finished(1)], [NO_ERROR])
        self.assertTrue(eof)
        at_eof = [t for t, seen in naks if seen and t == eof[0]]
        self.assertEqual(at_eof, [], "the gap asked for before EOF was NAKed again at EOF")
        self.assertTrue(any(not seen for _, seen in naks))  # the immediate NAK


if __name__ == "__main__":
    unittest.main()
