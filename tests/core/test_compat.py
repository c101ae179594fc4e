"""compat: the same clock and const behaviour on both interpreters."""

import unittest

from obsw import compat


class TestCompat(unittest.TestCase):
    def test_const_returns_its_argument(self):
        self.assertEqual(compat.const(42), 42)

    def test_ticks_diff_handles_wraparound(self):
        period = compat.TICKS_PERIOD
        self.assertEqual(compat.ticks_diff(5, period - 5), 10)
        self.assertEqual(compat.ticks_diff(period - 5, 5), -10)
        self.assertEqual(compat.ticks_diff(compat.ticks_add(period - 1, 2), period - 1), 2)

    def test_ticks_period_is_a_power_of_two(self):
        self.assertEqual(compat.TICKS_PERIOD & (compat.TICKS_PERIOD - 1), 0)
        self.assertEqual(compat.ticks_add(compat.TICKS_PERIOD - 1, 1), 0)

    def test_ticks_add_wraps(self):
        period = compat.TICKS_PERIOD
        self.assertEqual(compat.ticks_add(period - 1, 1), 0)
        self.assertEqual(compat.ticks_add(0, -1), period - 1)

    def test_clocks_do_not_go_backwards(self):
        a = compat.monotonic()
        t = compat.ticks_ms()
        b = compat.monotonic()
        self.assertTrue(b >= a)
        self.assertTrue(compat.ticks_diff(compat.ticks_ms(), t) >= 0)

    def test_interpreter_flag(self):
        import sys

        self.assertEqual(compat.MICROPYTHON, sys.implementation.name == "micropython")
