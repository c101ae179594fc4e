"""Recovery policy edges: the default boot grace to the second, a failure exactly one window
old, and a line switched on beside the active OBC (not a power cycle)."""

import unittest

from obsw.reconfig import recovery as R

EDGE = {"deadline": 1.0, "boot_grace": 2.0, "off_ms": 0, "max_failures": 2, "window": 10.0}


class TestDefaults(unittest.TestCase):
    def test_boot_grace_is_30_s(self):
        p = R.Recovery()
        p.start(0.0)
        self.assertIsNone(p.poll(29.5, 0x001))
        self.assertEqual(p.poll(30.0, 0x001)[0], R.POWER_CYCLE)

    def three_power_cycles(self):
        """The defaults' power cycles at 30, 61 and 92 s (boot grace 30 s, 1 s off)."""
        p = R.Recovery()
        p.start(0.0)
        for t in (30.0, 61.0, 92.0):
            self.assertEqual(p.poll(t, 0x001)[0], R.POWER_CYCLE)
            p.done(t, True)
        self.assertEqual(p.failures, [30.0, 61.0, 92.0])
        return p

    def test_the_window_is_900_s_and_a_failure_that_old_is_forgotten(self):
        p = self.three_power_cycles()
        p.heartbeat(R.SOURCE_UART, 920.0)
        self.assertIsNone(p.poll(929.5, 0x001))  # the deadline is 10 s
        self.assertEqual(p.poll(930.0, 0x001)[0], R.POWER_CYCLE)  # 930 - 30 = the window
        self.assertEqual(p.failures, [61.0, 92.0])

    def test_three_failures_within_900_s_switch_over(self):
        p = self.three_power_cycles()
        p.heartbeat(R.SOURCE_UART, 919.0)
        self.assertEqual(p.poll(929.0, 0x001)[0], R.SWITCH_OVER)

    def test_heartbeats_are_kept_per_source(self):
        p = R.Recovery()
        p.start(0.0)
        p.heartbeat(R.SOURCE_UART, 5.0)
        self.assertEqual(p.last_seen, [None, 5.0])
        p.heartbeat(R.SOURCE_CAN, 6.0)
        self.assertEqual(p.last_seen, [6.0, 5.0])


class TestWindow(unittest.TestCase):
    def two_failures(self):
        """Power cycles at 2 s and 4 s, then heartbeats; the policy and nothing pending."""
        p = R.Recovery(EDGE)
        p.start(0.0)
        self.assertEqual(p.poll(2.0, 0x001)[0], R.POWER_CYCLE)
        p.done(2.0, True)
        self.assertEqual(p.poll(4.0, 0x001)[0], R.POWER_CYCLE)
        p.done(4.0, True)
        self.assertEqual(p.failures, [2.0, 4.0])
        return p

    def test_a_failure_exactly_one_window_old_is_forgotten(self):
        p = self.two_failures()
        p.heartbeat(R.SOURCE_UART, 11.0)
        self.assertEqual(p.poll(12.0, 0x001)[0], R.POWER_CYCLE)  # 12 - 2 = the window
        self.assertEqual(p.failures, [4.0])

    def test_a_failure_just_inside_the_window_counts(self):
        p = self.two_failures()
        p.heartbeat(R.SOURCE_UART, 10.5)
        self.assertEqual(p.poll(11.5, 0x001)[0], R.SWITCH_OVER)
        self.assertEqual(p.failures, [2.0, 4.0])


class TestLineChanges(unittest.TestCase):
    def test_the_redundant_obc_switched_on_beside_the_active_one(self):
        p = R.Recovery(EDGE)
        p.start(0.0)
        p.poll(1.0, 0x001)
        self.assertIsNone(p.poll(1.5, 0x003))
        self.assertEqual((p.failures, p.active), ([], 0))

    def test_the_active_obc_switched_off_is_a_power_cycle(self):
        p = R.Recovery(EDGE)
        p.start(0.0)
        p.poll(1.0, 0x003)
        self.assertIsNone(p.poll(1.5, 0x002))
        self.assertEqual(p.failures, [1.5])


if __name__ == "__main__":
    unittest.main()


class TestDecisions(unittest.TestCase):
    def test_kinds_are_distinct_and_named(self):
        kinds = (R.POWER_CYCLE, R.SWITCH_OVER, R.STOOD_DOWN, R.FAILED)
        self.assertEqual([R.KIND_NAMES[k] for k in kinds],
                         ["power_cycle", "switch_over", "stood_down", "failed"])  # fmt: skip

    def test_decisions_count_one_by_one_and_uptime_defaults_to_zero(self):
        p = R.Recovery(EDGE)
        p.start(0.0)
        p.poll(2.0, 0x001)
        d = p.done(2.0, True)
        self.assertEqual((d.count, d.at_s), (1, 0))
        p.poll(4.0, 0x001)
        d = p.done(4.0, None, uptime_s=4.7)
        self.assertEqual((d.kind, d.count, d.at_s), (R.STOOD_DOWN, 2, 4))

    def test_after_a_power_cycle_the_line_off_time_and_boot_grace_pass(self):
        p = R.Recovery({"off_ms": 1000, "boot_grace": 30.0, "deadline": 10.0})
        p.start(0.0)
        self.assertEqual(p.poll(30.0, 0x001)[0], R.POWER_CYCLE)
        p.done(30.0, True)
        self.assertIsNone(p.poll(60.9995, 0x001))  # 1 s off and 30 s of grace: 61 s
        self.assertEqual(p.poll(61.0, 0x001)[0], R.POWER_CYCLE)

    def test_a_failed_write_is_tried_again_after_the_deadline(self):
        p = R.Recovery(EDGE)
        p.start(0.0)
        p.poll(2.0, 0x001)
        self.assertEqual(p.done(2.0, False).kind, R.FAILED)
        self.assertIsNone(p.poll(2.5, 0x001))
        self.assertEqual(p.poll(3.0, 0x001)[0], R.POWER_CYCLE)
