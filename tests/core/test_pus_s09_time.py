"""ST[09]: time reports at the rate the ground sets."""

import unittest

from obsw.pus.services.s01_verification import FAILURE_REFUSED
from obsw.pus.services.s09_time import TimeManagement, TimeUser
from obsw.store import Store
from pus_loop import APID, Loop
from store_sim import SimFs


def make(exponent=None, store=None):
    loop = Loop(store=store)
    s9 = loop.app.register(TimeManagement(exponent))
    user = loop.ground.register(TimeUser())
    return loop, s9, user


def run_for(loop, seconds, step=0.25):
    for _ in range(int(seconds / step)):
        loop.clock.advance(step)
        loop.app.tick()
    loop.pump()


class TestTime(unittest.TestCase):
    def test_no_reports_until_a_rate_is_set(self):
        loop, s9, user = make()
        run_for(loop, 10)
        self.assertEqual(loop.tm, [])

    def test_rate_and_report(self):
        loop, s9, user = make()
        self.assertTrue(loop.run(user.set_rate(APID, 1)).ok)
        run_for(loop, 8)
        reports = loop.unsolicited(9, 2)
        self.assertEqual(len(reports), 4)  # every 2 s, the first at once
        first = reports[0]
        self.assertEqual((first["exponent"], first["status"]), (1, 0))
        self.assertAlmostEqual(first["time"], 1000.25, 3)
        self.assertAlmostEqual(reports[1]["time"] - first["time"], 2.0, 3)

    def test_rate_change_restarts_the_schedule(self):
        loop, s9, user = make(3)
        run_for(loop, 1)
        loop.run(user.set_rate(APID, 0))
        run_for(loop, 3)
        self.assertEqual(len(loop.unsolicited(9, 2)), 4)

    def test_rate_too_slow_is_refused(self):
        loop, s9, user = make()
        tx = loop.run(user.set_rate(APID, 200))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)
        self.assertIsNone(s9.exponent)

    def test_rate_persists(self):
        fs = SimFs()
        loop, s9, user = make(store=Store("/ctx", fs))
        loop.run(user.set_rate(APID, 5))
        loop2, s9b, _ = make(store=Store("/ctx", fs))
        self.assertEqual(s9b.exponent, 5)


if __name__ == "__main__":
    unittest.main()
