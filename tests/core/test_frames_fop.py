"""FOP-1 (CCSDS 232.1-B-2 table 5-1): state transitions, alerts, and a lossy COP-1 loop."""

import unittest

from obsw.frames import farm as farm_mod
from obsw.frames import fop as F
from obsw.frames.clcw import Clcw


def notes_of(fop, kind):
    return [n for n in fop.take_notifications() if n[0] == kind]


def active(**kw):
    f = F.Fop1(1, 0, **kw)
    f.directive(F.INITIATE_AD_NO_CLCW, now=0)
    f.take_notifications()
    return f


def clcw(nr, **kw):
    return Clcw(vcid=0, report=nr, **kw)


class TestInitiation(unittest.TestCase):
    def test_initial_state_rejects_data(self):
        f = F.Fop1(1, 0)
        self.assertEqual(f.state, F.INITIAL)
        rid = f.send_ad(b"x", now=0)
        self.assertEqual(f.take_notifications(), [(F.REJECT, rid, None)])
        self.assertEqual(f.take_frames(), [])

    def test_e23_initiate_without_clcw(self):
        f = F.Fop1(1, 0)
        rid = f.directive(F.INITIATE_AD_NO_CLCW, now=0)
        self.assertEqual(f.state, F.ACTIVE)
        kinds = [(n[0], n[1]) for n in f.take_notifications()]
        self.assertEqual(kinds, [(F.ACCEPT, rid), (F.POSITIVE_CONFIRM, rid)])
        rid2 = f.directive(F.INITIATE_AD_NO_CLCW, now=0)
        self.assertEqual(f.take_notifications(), [(F.REJECT, rid2, None)])

    def test_e24_initiate_with_clcw(self):
        f = F.Fop1(1, 0, t1=5)
        f.directive(F.SET_VS, 9, now=0)
        rid = f.directive(F.INITIATE_AD_WITH_CLCW, now=0)
        self.assertEqual((f.state, f.deadline), (F.INITIALIZING_NO_BC, 5))
        f.on_clcw(clcw(9), now=1)  # E1
        self.assertEqual((f.state, f.deadline), (F.ACTIVE, None))
        self.assertIn((F.POSITIVE_CONFIRM, rid, None), f.take_notifications())

    def test_e24_times_out(self):
        f = F.Fop1(1, 0, t1=5)
        rid = f.directive(F.INITIATE_AD_WITH_CLCW, now=0)
        f.take_notifications()
        f.tick(4.9)
        self.assertEqual(f.state, F.INITIALIZING_NO_BC)
        f.tick(5)
        self.assertEqual(f.state, F.INITIAL)
        self.assertEqual(
            f.take_notifications(), [(F.NEGATIVE_CONFIRM, rid, None), (F.ALERT, None, F.ALERT_T1)]
        )

    def test_e24_wrong_nr_alerts(self):
        f = F.Fop1(1, 0)
        f.directive(F.INITIATE_AD_WITH_CLCW, now=0)
        f.on_clcw(clcw(4), now=1)  # N(R) != V(S): E13
        self.assertEqual(f.state, F.INITIAL)
        self.assertEqual(notes_of(f, F.ALERT), [(F.ALERT, None, F.ALERT_NNR)])

    def test_e25_unlock(self):
        f = F.Fop1(1, 0, t1=2, transmission_limit=2)
        rid = f.directive(F.INITIATE_AD_WITH_UNLOCK, now=0)
        frames = f.take_frames()
        self.assertEqual(len(frames), 1)
        self.assertEqual((frames[0].type_name, frames[0].data), ("BC", b"\x00"))
        self.assertEqual(f.state, F.INITIALIZING_WITH_BC)
        f.on_clcw(clcw(0, lockout=True), now=0.5)  # stale lockout CLCW: ignored in S5
        self.assertEqual(f.state, F.INITIALIZING_WITH_BC)
        f.tick(2)  # E16: BC frame retransmitted
        self.assertEqual([fr.data for fr in f.take_frames()], [b"\x00"])
        f.on_clcw(clcw(0), now=3)
        self.assertEqual(f.state, F.ACTIVE)
        self.assertIn((F.POSITIVE_CONFIRM, rid, None), f.take_notifications())

    def test_e25_bc_transmission_limit(self):
        f = F.Fop1(1, 0, t1=1, transmission_limit=2)
        f.directive(F.INITIATE_AD_WITH_UNLOCK, now=0)
        f.tick(1)
        f.tick(2)  # E17: Transmission_Count reached the limit
        self.assertEqual(f.state, F.INITIAL)
        self.assertEqual(notes_of(f, F.ALERT), [(F.ALERT, None, F.ALERT_T1)])
        self.assertEqual(len(f.take_frames()), 2)

    def test_e27_set_vr(self):
        f = F.Fop1(1, 0)
        f.directive(F.INITIATE_AD_WITH_SET_VR, 200, now=0)
        fr = f.take_frames()[0]
        self.assertEqual((fr.type_name, fr.data), ("BC", b"\x82\x00\xc8"))
        self.assertEqual((f.vs, f.nnr, f.state), (200, 200, F.INITIALIZING_WITH_BC))
        f.on_clcw(clcw(200), now=1)
        self.assertEqual(f.state, F.ACTIVE)
        f.send_ad(b"a", now=1)
        self.assertEqual(f.take_frames()[0].seq, 200)

    def test_set_vs_only_in_initial(self):
        f = F.Fop1(1, 0)
        f.directive(F.SET_VS, 17)
        self.assertEqual((f.vs, f.nnr), (17, 17))
        f = active()
        rid = f.directive(F.SET_VS, 3)
        self.assertEqual(f.take_notifications(), [(F.REJECT, rid, None)])


class TestActive(unittest.TestCase):
    def test_transmit_and_acknowledge(self):
        f = active(t1=3)
        ids = []
        for k in range(3):
            ids.append(f.send_ad(b"%d" % k, now=0))
        self.assertEqual([fr.seq for fr in f.take_frames()], [0, 1, 2])
        self.assertEqual((f.vs, f.outstanding, f.deadline), (3, 3, 3))
        f.on_clcw(clcw(2), now=1)  # E6: some acknowledged
        self.assertEqual((f.last_event, f.nnr, f.state), (6, 2, F.ACTIVE))
        confirmed = [n[1] for n in notes_of(f, F.POSITIVE_CONFIRM)]
        self.assertEqual(confirmed, ids[:2])
        f.on_clcw(clcw(2), now=1.5)  # E5: nothing new
        self.assertEqual(f.last_event, 5)
        f.on_clcw(clcw(3), now=2)  # E2: all acknowledged, timer stopped
        self.assertEqual((f.last_event, f.nnr, f.deadline), (2, 3, None))
        f.on_clcw(clcw(3), now=2)  # E1
        self.assertEqual((f.last_event, f.state), (1, F.ACTIVE))

    def test_sliding_window_and_wait_queue(self):
        f = active(window=2)
        f.send_ad(b"a", now=0)
        f.send_ad(b"b", now=0)
        self.assertTrue(f.ready)
        rid = f.send_ad(b"c", now=0)  # E19: waits, window full
        self.assertFalse(f.ready)
        self.assertEqual(len(f.take_frames()), 2)
        rid2 = f.send_ad(b"d", now=0)  # E20: Wait_Queue occupied
        self.assertIn((F.REJECT, rid2, None), f.take_notifications())
        f.on_clcw(clcw(1), now=1)
        frames = f.take_frames()
        self.assertEqual([(fr.seq, fr.data) for fr in frames], [(2, b"c")])
        self.assertIn((F.ACCEPT, rid, None), f.take_notifications())

    def test_e8_retransmit_after_negative_acknowledgement(self):
        f = active()
        for k in range(3):
            f.send_ad(b"%d" % k, now=0)
        f.take_frames()
        f.on_clcw(clcw(1, retransmit=True), now=1)  # E8: ack 0, resend 1 and 2
        self.assertEqual(
            (f.last_event, f.state, f.transmission_count), (8, F.RETRANSMIT_NO_WAIT, 2)
        )
        self.assertEqual([fr.seq for fr in f.take_frames()], [1, 2])
        self.assertEqual(len(notes_of(f, F.ABORT)), 1)  # queued frames of the lower layer dropped
        f.on_clcw(clcw(1, retransmit=True), now=1.1)  # E10 in S2: ignore
        self.assertEqual((f.last_event, f.take_frames()), (10, []))
        f.on_clcw(clcw(3), now=2)  # E2: back to Active
        self.assertEqual(f.state, F.ACTIVE)

    def test_e10_e11_e12_wait_and_limit(self):
        f = active(transmission_limit=2)
        f.send_ad(b"x", now=0)
        f.take_frames()
        f.on_clcw(clcw(0, retransmit=True, wait=True), now=1)  # E11 -> S3
        self.assertEqual((f.last_event, f.state), (11, F.RETRANSMIT_WITH_WAIT))
        f.tick(100)  # E16 in S3: ignored
        self.assertEqual(f.take_frames(), [])
        f.on_clcw(clcw(0, retransmit=True), now=101)  # E10 in S3: retransmit -> S2
        self.assertEqual((f.last_event, f.state, len(f.take_frames())), (10, 2, 1))
        f.on_clcw(clcw(0, retransmit=True), now=102)  # E12: count at limit, S2 ignores
        self.assertEqual((f.last_event, f.state), (12, F.RETRANSMIT_NO_WAIT))
        f.on_clcw(clcw(0, retransmit=True, wait=True), now=103)  # E103 -> S3
        self.assertEqual((f.last_event, f.state), (103, F.RETRANSMIT_WITH_WAIT))
        f.on_clcw(clcw(0), now=104)  # E5 in S3: SYNCH
        self.assertEqual(f.state, F.INITIAL)
        self.assertEqual(notes_of(f, F.ALERT)[-1][2], F.ALERT_SYNCH)

    def test_e9_wait(self):
        f = active()
        f.send_ad(b"a", now=0)
        f.send_ad(b"b", now=0)
        f.on_clcw(clcw(1, retransmit=True, wait=True), now=1)
        self.assertEqual((f.last_event, f.state, f.nnr), (9, F.RETRANSMIT_WITH_WAIT, 1))

    def test_transmission_limit_one(self):
        f = active(transmission_limit=1)
        ids = [f.send_ad(b"a", now=0), f.send_ad(b"b", now=0)]
        f.on_clcw(clcw(1, retransmit=True), now=1)  # E101
        self.assertEqual((f.last_event, f.state), (101, F.INITIAL))
        notes = f.take_notifications()
        self.assertIn((F.POSITIVE_CONFIRM, ids[0], None), notes)
        self.assertIn((F.NEGATIVE_CONFIRM, ids[1], None), notes)
        self.assertEqual(notes[-1], (F.ALERT, None, F.ALERT_LIMIT))

    def test_alerts_from_clcw(self):
        cases = (
            (dict(wait=True), 0, 3, F.ALERT_CLCW),
            (dict(retransmit=True), 0, 4, F.ALERT_SYNCH),
            (dict(lockout=True), 0, 14, F.ALERT_LOCKOUT),
            ({}, 7, 13, F.ALERT_NNR),
            (dict(wait=True), 1, 7, F.ALERT_CLCW),
        )
        for flags, nr, event, code in cases:
            f = active()
            f.send_ad(b"a", now=0)
            f.send_ad(b"b", now=0)
            f.on_clcw(clcw(2 if nr == 0 else nr, **flags), now=1)
            self.assertEqual((f.last_event, f.state), (event, F.INITIAL))
            self.assertEqual(notes_of(f, F.ALERT), [(F.ALERT, None, code)])

    def test_clcw_of_other_vc_ignored_and_bad_cop_alerts(self):
        f = active()
        f.on_clcw(Clcw(vcid=3, report=99), now=1)
        self.assertEqual(f.state, F.ACTIVE)
        f.on_clcw(Clcw(vcid=0, report=0, cop=2), now=1)  # E15
        self.assertEqual((f.last_event, f.state), (15, F.INITIAL))

    def test_timer_retransmission_then_t1_alert(self):
        f = active(t1=1, transmission_limit=3)
        rid = f.send_ad(b"a", now=0)
        f.take_frames()
        f.tick(1)  # E16
        self.assertEqual((f.last_event, f.transmission_count, len(f.take_frames())), (16, 2, 1))
        f.tick(2)
        f.tick(3)  # E17
        self.assertEqual((f.last_event, f.state), (17, F.INITIAL))
        notes = f.take_notifications()
        self.assertIn((F.NEGATIVE_CONFIRM, rid, None), notes)
        self.assertEqual(notes[-1], (F.ALERT, None, F.ALERT_T1))

    def test_suspend_and_resume(self):
        f = active(t1=1, transmission_limit=1, timeout_type=1)
        f.send_ad(b"a", now=0)
        f.take_frames()
        f.tick(1)  # E18: suspend remembering S1
        self.assertEqual((f.state, f.suspend_state), (F.INITIAL, F.ACTIVE))
        self.assertEqual(notes_of(f, F.SUSPEND), [(F.SUSPEND, None, F.ACTIVE)])
        f.directive(F.RESUME_AD, now=5)  # E31
        self.assertEqual((f.state, f.suspend_state, f.deadline), (F.ACTIVE, 0, 6))
        f.on_clcw(clcw(1), now=5.5)
        self.assertEqual(f.outstanding, 0)
        rid = f.directive(F.RESUME_AD, now=6)  # E30: nothing suspended
        self.assertEqual(f.take_notifications()[-1], (F.REJECT, rid, None))

    def test_terminate(self):
        f = active()
        rid_fdu = f.send_ad(b"a", now=0)
        f.take_notifications()
        rid = f.directive(F.TERMINATE_AD, now=1)
        self.assertEqual(f.state, F.INITIAL)
        self.assertEqual(
            f.take_notifications(),
            [
                (F.ACCEPT, rid, None),
                (F.NEGATIVE_CONFIRM, rid_fdu, None),
                (F.ALERT, None, F.ALERT_TERM),
                (F.POSITIVE_CONFIRM, rid, None),
            ],
        )

    def test_bd_service_in_any_state(self):
        f = F.Fop1(1, 0)
        rid = f.send_bd(b"urgent", now=0)
        fr = f.take_frames()[0]
        self.assertEqual((fr.type_name, fr.data), ("BD", b"urgent"))
        self.assertEqual(f.take_notifications(), [(F.ACCEPT, rid, None)])

    def test_setters(self):
        f = F.Fop1(1, 0)
        f.directive(F.SET_WINDOW, 7)
        f.directive(F.SET_T1, 4.5)
        f.directive(F.SET_TRANSMISSION_LIMIT, 9)
        f.directive(F.SET_TIMEOUT_TYPE, 1)
        self.assertEqual((f.window, f.t1, f.transmission_limit, f.timeout_type), (7, 4.5, 9, 1))
        rid = f.directive(F.SET_WINDOW, 0)  # E40: invalid
        self.assertEqual(f.take_notifications()[-1], (F.REJECT, rid, None))


class TestLowerProcedures(unittest.TestCase):
    def test_manual_accept(self):
        f = F.Fop1(1, 0, auto_accept=False)
        f.directive(F.INITIATE_AD_NO_CLCW, now=0)
        f.send_ad(b"a", now=0)
        self.assertEqual(len(f.take_frames()), 1)
        f.on_clcw(clcw(1), now=0)
        f.send_ad(b"b", now=0)  # AD_Out not ready: stays in the Wait_Queue
        self.assertEqual(f.take_frames(), [])
        f.lower_response(0, True)  # E41
        self.assertEqual([fr.data for fr in f.take_frames()], [b"b"])

    def test_reject_is_llif(self):
        f = active()
        f.lower_response(0, False)
        self.assertEqual((f.last_event, f.state), (42, F.INITIAL))
        self.assertEqual(notes_of(f, F.ALERT), [(F.ALERT, None, F.ALERT_LLIF)])


class _Rng:
    def __init__(self, seed):
        self.s = seed

    def below(self, n):
        self.s = (self.s * 1103515245 + 12345) & 0x7FFFFFFF
        return (self.s >> 8) % n


def run_link(seed, count=40, loss=20, dup=20, clcw_loss=30, reorder=3):
    """FOP-1 and FARM-1 over an uplink that loses, duplicates and reorders frames and a
    downlink that loses, duplicates and reorders CLCWs (the ground keeps only the newest)."""
    rng = _Rng(seed)
    fop = F.Fop1(1, 0, window=4, t1=1.0, transmission_limit=1000)
    farm = farm_mod.Farm1(0, window=10)
    fop.directive(F.INITIATE_AD_NO_CLCW, now=0)
    todo = [b"fdu%03d" % i for i in range(count)]
    delivered = []
    uplink = []
    downlink = []
    newest = -1
    now = 0.0
    sent = 0
    for step in range(20000):
        now += 0.05
        if todo and fop.ready:
            fop.send_ad(todo.pop(0), now)
        for fr in fop.take_frames():
            sent += 1
            if rng.below(100) < loss:
                continue
            copies = 2 if rng.below(100) < dup else 1
            for _ in range(copies):
                # reordering within a few frames, as between two links of different latency
                uplink.insert(len(uplink) - rng.below(min(reorder, len(uplink)) + 1), fr)
        for _ in range(min(3, len(uplink))):
            farm.on_frame(uplink.pop(0))
            while True:
                got = farm.take()
                if got is None:
                    break
                delivered.append(got.data)
            if rng.below(100) >= clcw_loss:
                for _ in range(1 + (rng.below(100) < dup)):
                    downlink.insert(rng.below(len(downlink) + 1), (step, farm.clcw()))
        if downlink and rng.below(2):
            seq, c = downlink.pop(0)
            if seq > newest:  # TM frame counters order the CLCWs on the ground
                newest = seq
                fop.on_clcw(c, now)
        fop.tick(now)
        for n in fop.take_notifications():
            if n[0] in (F.ALERT, F.SUSPEND):
                raise AssertionError("unexpected %s %r" % (F.NOTIFICATION_NAMES[n[0]], n))
        if not todo and fop.outstanding == 0 and fop.ready:
            break
    return delivered, sent


class TestScenario(unittest.TestCase):
    def test_every_frame_delivered_once_in_order(self):
        for seed in (1, 2, 3, 4, 5):
            delivered, sent = run_link(seed)
            self.assertEqual(delivered, [b"fdu%03d" % i for i in range(40)])
            self.assertTrue(sent > 40)  # losses were repaired by retransmission

    def test_clean_link_sends_each_frame_once(self):
        delivered, sent = run_link(9, count=30, loss=0, dup=0, clcw_loss=0, reorder=0)
        self.assertEqual(len(delivered), 30)
        self.assertEqual(sent, 30)


if __name__ == "__main__":
    unittest.main()
