"""FARM-1 (CCSDS 232.1-B-2 table 6-1): every event in every state, and the CLCW it reports."""

import unittest

from obsw.frames import farm
from obsw.frames.tc import UNLOCK, TcFrame, set_vr_command


def ad(ns, data=b"x"):
    return TcFrame(1, 0, data, ns)


def bd(data=b"b"):
    return TcFrame(1, 0, data, 0, True)


def bc(data):
    return TcFrame(1, 0, data, 0, True, True)


def farm_in(state, vr=10, buffer_size=4):
    f = farm.Farm1(0, window=10, buffer_size=buffer_size)
    f.vr = vr
    if state == farm.WAIT:
        for _ in range(buffer_size):
            f.on_frame(ad(f.vr))
        f.on_frame(ad(f.vr))  # no buffer: E2 -> Wait
        f.retransmit = False  # isolate the flag under test
    elif state == farm.LOCKOUT:
        f.on_frame(ad((vr + 100) & 0xFF))
    return f


class TestOpen(unittest.TestCase):
    def test_e1_accept(self):
        f = farm_in(farm.OPEN)
        f.retransmit = True
        self.assertEqual(f.on_frame(ad(10, b"data")), farm.ACCEPT)
        self.assertEqual((f.last_event, f.vr, f.retransmit, f.state), (1, 11, False, farm.OPEN))
        self.assertEqual(f.take().data, b"data")
        self.assertIsNone(f.take())

    def test_e2_no_buffer_goes_to_wait(self):
        f = farm_in(farm.OPEN, buffer_size=1)
        f.on_frame(ad(10))
        self.assertEqual(f.on_frame(ad(11)), farm.DISCARD)
        self.assertEqual(f.last_event, 2)
        self.assertEqual((f.state, f.wait, f.retransmit, f.vr), (farm.WAIT, True, True, 11))

    def test_e3_positive_window(self):
        f = farm_in(farm.OPEN)
        self.assertEqual(f.on_frame(ad(14)), farm.DISCARD)  # V(R)+PW-1 is the edge
        self.assertEqual((f.last_event, f.retransmit, f.state), (3, True, farm.OPEN))

    def test_e4_negative_window(self):
        f = farm_in(farm.OPEN)
        for ns in (9, 5):
            self.assertEqual(f.on_frame(ad(ns)), farm.DISCARD)
            self.assertEqual((f.last_event, f.retransmit, f.state), (4, False, farm.OPEN))

    def test_e5_lockout_area(self):
        for ns in (15, 4, 200):
            f = farm_in(farm.OPEN)
            self.assertEqual(f.on_frame(ad(ns)), farm.DISCARD)
            self.assertEqual((f.last_event, f.lockout, f.state), (5, True, farm.LOCKOUT))

    def test_window_wraps_modulo_256(self):
        f = farm_in(farm.OPEN, vr=254)
        f.on_frame(ad(2))
        self.assertEqual(f.last_event, 3)
        f.on_frame(ad(250))
        self.assertEqual(f.last_event, 4)
        f.on_frame(ad(254))
        f.on_frame(ad(255))
        self.assertEqual((f.last_event, f.vr), (1, 0))

    def test_e6_bd_accepted_and_counted(self):
        f = farm_in(farm.OPEN)
        for n in range(1, 6):
            self.assertEqual(f.on_frame(bd()), farm.ACCEPT)
            self.assertEqual(f.farm_b, n)
        self.assertEqual(f.clcw().farm_b, 5 & 3)
        self.assertEqual(f.vr, 10)

    def test_e7_unlock(self):
        f = farm_in(farm.OPEN)
        f.retransmit = True
        self.assertEqual(f.on_frame(bc(UNLOCK)), farm.ACCEPT)
        self.assertEqual((f.last_event, f.retransmit, f.farm_b), (7, False, 1))

    def test_e8_set_vr(self):
        f = farm_in(farm.OPEN)
        f.retransmit = True
        f.on_frame(bc(set_vr_command(77)))
        self.assertEqual((f.last_event, f.vr, f.retransmit, f.farm_b), (8, 77, False, 1))

    def test_e9_invalid_control_command(self):
        f = farm_in(farm.OPEN)
        self.assertEqual(f.on_frame(bc(b"\x82\x01\x00")), farm.DISCARD)
        self.assertEqual((f.last_event, f.farm_b), (9, 0))
        self.assertEqual(f.on_frame(TcFrame(1, 0, b"x", 10, False, True)), farm.DISCARD)
        self.assertEqual(f.last_event, 9)


class TestWait(unittest.TestCase):
    def test_e2_e3_discard(self):
        f = farm_in(farm.WAIT)
        vr = f.vr
        f.on_frame(ad(vr))
        self.assertEqual((f.last_event, f.state), (2, farm.WAIT))
        f.on_frame(ad(vr + 2))
        self.assertEqual((f.last_event, f.state, f.retransmit), (3, farm.WAIT, False))

    def test_e5_to_lockout(self):
        f = farm_in(farm.WAIT)
        f.on_frame(ad(f.vr + 100))
        self.assertEqual((f.state, f.lockout, f.wait), (farm.LOCKOUT, True, True))

    def test_e7_unlock_clears_wait(self):
        f = farm_in(farm.WAIT)
        f.retransmit = True
        f.on_frame(bc(UNLOCK))
        self.assertEqual((f.state, f.wait, f.retransmit), (farm.OPEN, False, False))

    def test_e8_set_vr_clears_wait(self):
        f = farm_in(farm.WAIT)
        f.on_frame(bc(set_vr_command(3)))
        self.assertEqual((f.state, f.wait, f.vr), (farm.OPEN, False, 3))

    def test_e10_buffer_release(self):
        f = farm_in(farm.WAIT)
        self.assertIsNotNone(f.take())
        self.assertEqual(f.last_event, 10)
        self.assertEqual((f.state, f.wait), (farm.OPEN, False))
        self.assertEqual(f.on_frame(ad(f.vr)), farm.ACCEPT)

    def test_bd_accepted_while_waiting(self):
        f = farm_in(farm.WAIT)
        self.assertEqual(f.on_frame(bd()), farm.ACCEPT)


class TestLockout(unittest.TestCase):
    def test_ad_frames_discarded(self):
        f = farm_in(farm.LOCKOUT)
        for ns in (10, 12, 8, 150):
            self.assertEqual(f.on_frame(ad(ns)), farm.DISCARD)
            self.assertEqual(f.state, farm.LOCKOUT)
        self.assertEqual(f.vr, 10)

    def test_e8_set_vr_only_counted(self):
        f = farm_in(farm.LOCKOUT)
        self.assertEqual(f.on_frame(bc(set_vr_command(99))), farm.ACCEPT)
        self.assertEqual((f.state, f.vr, f.farm_b), (farm.LOCKOUT, 10, 1))

    def test_e7_unlock(self):
        f = farm_in(farm.LOCKOUT)
        f.on_frame(bc(UNLOCK))
        self.assertEqual(
            (f.state, f.lockout, f.wait, f.retransmit), (farm.OPEN, False, False, False)
        )

    def test_e10_clears_wait_only(self):
        f = farm_in(farm.WAIT)
        f.on_frame(ad(f.vr + 100))
        f.take()
        self.assertEqual((f.state, f.wait, f.lockout), (farm.LOCKOUT, False, True))


class TestClcwAndConfig(unittest.TestCase):
    def test_clcw_reports_state(self):
        f = farm_in(farm.LOCKOUT)
        f.no_rf = True
        c = f.clcw()
        self.assertEqual((c.vcid, c.report, c.lockout, c.wait, c.cop), (0, 10, True, False, 1))
        self.assertTrue(c.no_rf)

    def test_window_validation(self):
        for w in (1, 3, 256):
            with self.assertRaises(ValueError):
                farm.Farm1(0, window=w)
        f = farm.Farm1(0, window=20, positive=5, negative=2)
        f.on_frame(ad(5))
        self.assertEqual(f.last_event, 5)

    def test_reset(self):
        f = farm_in(farm.LOCKOUT)
        f.reset()
        self.assertEqual((f.state, f.vr, f.lockout, f.farm_b), (farm.OPEN, 0, False, 0))


class TestBdFramesBounded(unittest.TestCase):
    def test_a_full_buffer_discards_the_new_bd_frame_and_keeps_the_ad_count(self):
        f = farm_in(farm.OPEN, buffer_size=2)
        self.assertEqual(f.on_frame(ad(f.vr)), farm.ACCEPT)
        room = f._capacity - 1
        for _ in range(room):
            self.assertEqual(f.on_frame(bd()), farm.ACCEPT)
        self.assertEqual(f.on_frame(bd()), farm.DISCARD)  # one above: discarded, counted
        self.assertEqual(f.bd_dropped, 1)
        self.assertEqual(f._held, 1)
        self.assertEqual(f.take().frame_type, ad(0).frame_type)  # the AD frame was kept
        self.assertEqual(f._held, 0)
        self.assertEqual(f.on_frame(bd()), farm.ACCEPT)  # room again
        self.assertEqual(f.on_frame(ad(f.vr)), farm.ACCEPT)
        self.assertEqual(f.on_frame(ad(f.vr)), farm.ACCEPT)  # two AD frames: buffer_size
        self.assertEqual(f.on_frame(ad(f.vr)), farm.DISCARD)  # the third: Wait, as before
        self.assertEqual(f.state, farm.WAIT)


if __name__ == "__main__":
    unittest.main()
