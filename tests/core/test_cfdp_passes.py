"""CFDP across passes: class 2 transfers larger than one pass, both ways at once, suspended at
LOS and resumed at AOS (obsw.cfdp.contact.PassHold), timers frozen out of contact; without the
hold the same transfers run their timers out and are not completed."""

import unittest

from cfdp_sim import Link, make_pair, payload
from obsw.cfdp.contact import PassHold
from obsw.cfdp.defs import ACKNOWLEDGED, DATA_COMPLETE, NO_ERROR
from obsw.frames.contact import AOS, LOS, Contact

DOWN = payload(30000, seed=3)  # a to b: about three passes at the link's rate
UP = payload(15000, seed=4)  # b to a: about two
PASS = 6.0  # seconds in contact
PERIOD = 200.0  # seconds from AOS to AOS: far longer than the inactivity timer (30 s)
WINDOWS = [(50.0 + i * PERIOD, 50.0 + i * PERIOD + PASS) for i in range(12)]


def fly(hold=True, limit=8000.0, early=0.0):
    """``early``: the receiving side's passes end that many seconds before the sender's (it
    is suspended while PDUs still come: a late frame, a sender that has not heard LOS)."""
    a, b = make_pair(files_a={"down.bin": DOWN}, files_b={"up.bin": UP}, mode=ACKNOWLEDGED)
    a.put(2, "down.bin", "down.bin")
    b.put(1, "up.bin", "up.bin")
    link = Link(a, b, drop=lambda side, pdu: not contacts[side].contact(link.now))
    contacts = [Contact(hold=0.5), Contact(hold=0.5)]
    holds = [PassHold(a), PassHold(b)]
    contacts[0].load(WINDOWS)
    contacts[1].load([(s, e - early) for s, e in WINDOWS])
    edges = []
    while link.now < limit:
        for side in (0, 1):
            e = contacts[side].update(link.now)
            if e is not None:
                edges.append((side, e, link.now))
            if hold:
                holds[side].update(contacts[side].in_contact, link.now)
        link.step()  # at most 32 PDUs each way per second: ~2 KB/s of file data
        for side in (0, 1):
            (a, b)[side].poll(link.now)
            link.indications[side].extend((a, b)[side].pop_indications())
        if not a.tx and not b.tx:
            break
        link.now += 1.0
    return a, b, link, holds, edges


class TestCfdpAcrossPasses(unittest.TestCase):
    def test_both_ways_across_passes_complete_and_never_restart(self):
        a, b, link, holds, edges = fly()
        self.assertEqual(bytes(b.fs.files["down.bin"]), DOWN)
        self.assertEqual(bytes(a.fs.files["up.bin"]), UP)
        for side in (0, 1):
            fin = link.finished(side)
            self.assertEqual(len(fin), 2)  # its sender's and its receiver's
            for f in fin:
                self.assertEqual(f.info["condition"], NO_ERROR)
            for f in fin:
                if "delivery" in f.info:
                    self.assertEqual(f.info["delivery"], DATA_COMPLETE)
        # the big file took at least three passes, each resumed where it stopped
        self.assertTrue(holds[0].resumes >= 2)
        progress = [i.info["progress"] for i in link.kinds(0, "resumed")]
        self.assertTrue(len(progress) >= 2)
        self.assertTrue(all(p > 0 for p in progress[1:]))
        self.assertEqual(progress, sorted(progress))
        self.assertEqual(holds[0].suspends, holds[0].resumes)
        self.assertEqual([e for e in edges if e[1] not in (AOS, LOS)], [])
        self.assertEqual(a.tx, {})
        self.assertEqual(b.tx, {})

    def test_without_the_hold_the_timers_run_out(self):
        a, b, link, holds, edges = fly(hold=False, limit=3000.0)
        self.assertTrue(bytes(b.fs.files.get("down.bin", b"")) != DOWN)
        faults = [i.info["condition"] for i in link.kinds(0, "fault")]
        self.assertTrue(len(faults) >= 1)
        self.assertTrue(all(c != NO_ERROR for c in faults))
        self.assertTrue(len(link.kinds(0, "abandoned")) >= 1)  # its sender gave up

    def test_pdus_that_reach_a_suspended_receiver_move_no_timer(self):
        # b's passes end before a's: a's file data reach b suspended; its inactivity timer
        # must not run from them through the 194 s out of contact (it is 30 s)
        a, b, link, holds, edges = fly(early=2.0)
        self.assertEqual(bytes(b.fs.files["down.bin"]), DOWN)
        self.assertEqual(link.kinds(1, "fault"), [])

    def test_a_timer_started_while_suspended_runs_from_the_resume(self):
        from obsw.cfdp.timers import Timer

        t = Timer(30.0)
        t.start(0.0)
        t.suspend(10.0)
        t.start(12.0)  # a PDU while suspended
        self.assertFalse(t.expired(1000.0))
        t.resume(1000.0)
        self.assertFalse(t.expired(1029.0))
        self.assertTrue(t.expired(1030.0))

    def test_a_transfer_the_user_suspended_stays_suspended(self):
        a, b = make_pair(files_a={"down.bin": DOWN}, mode=ACKNOWLEDGED)
        tid = a.put(2, "down.bin", "down.bin")
        hold = PassHold(a)
        a.suspend(tid, 1.0)
        hold.edge(LOS, 2.0)
        hold.edge(AOS, 3.0)
        self.assertTrue(a.find(tid).suspended)
        self.assertEqual(hold.resumes, 0)


if __name__ == "__main__":
    unittest.main()
