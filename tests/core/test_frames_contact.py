"""Contact awareness (obsw.frames.contact) and store-and-forward across passes
(obsw.frames.downlink.StoreForward over ST[15] packet stores)."""

import unittest

from obsw.frames.contact import AOS, LOS, MAX_WINDOWS, Contact, PassTableError
from obsw.frames.downlink import RESEND_RANGES, StoreForward
from obsw.pus.services.packet_store import BOUNDED, PacketStore


class TestContact(unittest.TestCase):
    def test_pass_table_edges(self):
        c = Contact(hold=5.0)
        c.load([(100, 200), (300, 400)])
        self.assertIsNone(c.update(99.9))
        self.assertEqual(c.update(100.0), AOS)  # AOS is in the window
        self.assertIsNone(c.update(199.9))
        self.assertEqual(c.update(200.0), LOS)  # LOS is not
        self.assertEqual(c.update(300.0), AOS)
        self.assertEqual(c.left(350.0), 50.0)
        self.assertEqual(c.aos_count, 2)

    def test_the_link_holds_contact_for_hold_seconds(self):
        c = Contact(hold=5.0)
        c.heard(10.0)
        self.assertEqual(c.update(10.0), AOS)
        self.assertEqual(c.left(12.0), 5.0)
        self.assertIsNone(c.update(14.999))
        self.assertEqual(c.update(15.0), LOS)
        c.carrier(True, 20.0)
        self.assertEqual(c.update(100.0), AOS)  # the carrier holds as long as it is on
        c.carrier(False, 101.0)
        self.assertEqual(c.update(106.0), LOS)

    def test_a_late_tc_keeps_contact_after_the_table_los(self):
        c = Contact(hold=5.0)
        c.load([(0, 10)])
        c.update(0)
        c.heard(9.0)
        self.assertIsNone(c.update(12.0))
        self.assertEqual(c.update(14.0), LOS)

    def test_bad_tables(self):
        c = Contact()
        with self.assertRaises(PassTableError):
            c.load([(10, 10)])
        with self.assertRaises(PassTableError):
            c.load([(0, 10), (9, 20)])
        with self.assertRaises(PassTableError):
            c.load([(i * 10, i * 10 + 1) for i in range(MAX_WINDOWS + 1)])
        c.load([(i * 10, i * 10 + 1) for i in range(MAX_WINDOWS)])  # the edge fits
        c.load([(0, 10), (10, 20)])  # touching windows are disjoint
        self.assertEqual(len(c.windows), 2)


def _stores():
    events = PacketStore(1, 10000, BOUNDED)
    hk = PacketStore(2, 10000, BOUNDED)
    return events, hk


def _packet(tag, n=100):
    return bytes([tag]) * n


def _in_a_long_pass(hk_packets, bps):
    """The stores and a forwarder in a pass of 1000 s, ``hk_packets`` in store 2."""
    events, hk = _stores()
    c = Contact()
    c.load([(0, 1000)])
    for i in range(hk_packets):
        hk.append(float(i), _packet(2))
    return hk, StoreForward([events, hk], c, bps=bps)


def _drain(fw, now):
    """The storage sequence numbers ``fw`` sends at ``now`` until it has nothing to send."""
    seqs = []
    while True:
        got = fw.next(now)
        if got is None:
            return seqs
        seqs.append(got[1])


class TestStoreForward(unittest.TestCase):
    def test_nothing_leaves_out_of_contact_then_priority_first(self):
        events, hk = _stores()
        c = Contact()
        c.load([(100, 110)])
        fw = StoreForward([events, hk], c, bps=8000)  # 1000 octets/s
        for i in range(5):
            hk.append(float(i), _packet(2))
        events.append(3.0, _packet(1))
        self.assertIsNone(fw.next(50.0))
        out = []
        while True:
            got = fw.next(100.0)
            if got is None:
                break
            out.append((got[0].id, got[1]))
        self.assertEqual(out, [(1, 1), (2, 1), (2, 2), (2, 3), (2, 4), (2, 5)])
        self.assertIsNone(fw.next(100.0))  # nothing is sent twice
        self.assertEqual(fw.backlog(), 0)

    def test_a_packet_that_does_not_fit_waits_for_the_next_pass(self):
        events, hk = _stores()
        c = Contact()
        c.load([(100, 101), (200, 201)])
        fw = StoreForward([events, hk], c, bps=8000)  # 1000 octets per pass
        for i in range(12):
            hk.append(float(i), _packet(2))
        sent = 0
        while fw.next(100.0, budget=1000 - 100 * sent) is not None:
            sent += 1
        self.assertEqual(sent, 10)  # 10 x 100 octets: the pass's volume, and no more
        self.assertEqual(fw.held, 1)
        self.assertEqual(fw.next(150.0), None)  # between passes
        rest = []
        while True:
            got = fw.next(200.0, budget=1000)
            if got is None:
                break
            rest.append(got[1])
        self.assertEqual(rest, [11, 12])  # where the last pass stopped

    def test_budget_edges(self):
        events, hk = _stores()
        c = Contact()
        c.load([(0, 100)])
        fw = StoreForward([events, hk], c, bps=8)
        hk.append(0.0, _packet(2, 10))
        self.assertIsNone(fw.next(0.0, budget=9))  # one below
        self.assertEqual(fw.next(0.0, budget=10)[1], 1)  # at the edge
        self.assertEqual(fw.budget(90.0), 10.0)  # 10 s left at 1 octet/s

    def test_resend_then_acknowledge(self):
        hk, fw = _in_a_long_pass(6, bps=80000)
        self.assertEqual(_drain(fw, 1.0), [1, 2, 3, 4, 5, 6])
        self.assertTrue(fw.resend(2, 3, 4))  # the ground lost 3 and 4
        self.assertEqual([fw.next(2.0)[1], fw.next(2.0)[1]], [3, 4])
        self.assertIsNone(fw.next(2.0))
        self.assertEqual(fw.resent, 2)
        self.assertEqual(fw.acknowledge(2, 6), 6)
        self.assertEqual(hk.used, 0)
        self.assertTrue(fw.resend(2, 1, 6))  # acknowledged: nothing left to resend
        self.assertIsNone(fw.next(3.0))
        with self.assertRaises(KeyError):
            fw.acknowledge(9, 1)

    def test_a_long_range_goes_again_and_ranges_are_bounded(self):
        _hk, fw = _in_a_long_pass(100, bps=800000)
        self.assertEqual(_drain(fw, 1.0), list(range(1, 101)))
        self.assertEqual(fw.acknowledge(2, 10), 10)
        self.assertTrue(fw.resend(2, 1, 100))  # 1 to 10 acknowledged since: 11 to 100 go
        self.assertTrue(fw.resend(2, 50, 49))  # an empty range: nothing, and not refused
        self.assertEqual(_drain(fw, 2.0), list(range(11, 101)))
        for _ in range(RESEND_RANGES):
            self.assertTrue(fw.resend(2, 11, 11))
        self.assertFalse(fw.resend(2, 12, 12))  # full: the ground asks again later
        self.assertEqual([fw.next(3.0)[1] for _ in range(RESEND_RANGES)], [11] * RESEND_RANGES)
        self.assertIsNone(fw.next(3.0))

    def test_a_full_bounded_store_refuses_and_counts(self):
        st = PacketStore(1, 250, BOUNDED)
        self.assertTrue(st.append(0.0, _packet(1)))
        self.assertTrue(st.append(1.0, _packet(1)))
        self.assertFalse(st.append(2.0, _packet(1)))
        self.assertEqual(st.rejected, 1)
        self.assertEqual(st.delete_through(1), 1)
        self.assertTrue(st.append(3.0, _packet(1)))


if __name__ == "__main__":
    unittest.main()
