"""ST[09]: time reports at the rate the ground sets."""

import unittest

from obsw.pus.services.s01_verification import FAILURE_REFUSED
from obsw.pus.services.s09_time import TimeManagement, TimeUser
from obsw.store import Store
from pus_loop import APID, Loop
from store_sim import SimFs


def make(exponent=None, store=None, code="cuc"):
    loop = Loop(store=store)
    s9 = loop.app.register(TimeManagement(exponent, code))
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

    def test_cds_time_reports(self):
        loop, s9, user = make(code="cds")
        loop.clock.advance(86400 * 3 + 0.5)  # day 3, 1000.5 s into it: the CDS fields change
        self.assertTrue(loop.run(user.set_rate(APID, 0)).ok)
        run_for(loop, 2, step=0.5)
        self.assertEqual(loop.unsolicited(9, 2), [])
        reports = loop.unsolicited(9, 3)
        self.assertEqual(len(reports), 2)  # every second, the first at once
        self.assertEqual((reports[0]["exponent"], reports[0]["status"]), (0, 0))
        self.assertAlmostEqual(reports[0]["time"], 86400 * 3 + 1001.0, 3)
        self.assertAlmostEqual(reports[1]["time"] - reports[0]["time"], 1.0, 3)
        raw = [r for r, t in zip(loop.raw, loop.tm) if (t.service, t.subtype) == (9, 3)][0]
        # exponent, day (16 bits), ms of day (32 bits: 1001000), status; then the CRC
        self.assertEqual(raw[-10:-2], bytes((0, 0, 3, 0, 0x0F, 0x46, 0x28, 0)))

    def test_unknown_time_code_is_refused_at_construction(self):
        with self.assertRaises(ValueError):
            TimeManagement(0, "gps")


if __name__ == "__main__":
    unittest.main()
