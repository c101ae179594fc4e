"""CPDU access by the modified Dekker algorithm: one controller alone, battles, a million
randomly interleaved scheduling steps of both, and a stuck request line recovered by reset."""

import unittest

from obsw.reconfig.cpdu import IDLE, Cpdu, CpduBusyError
from obsw.reconfig.dekker_sim import DekkerSim
from obsw.reconfig.hal import NOMINAL, REDUNDANT
from obsw.reconfig.models import ModelHal


class TestAlone(unittest.TestCase):
    def test_write_latches_the_masked_lines(self):
        hal = ModelHal()
        c = Cpdu(hal, NOMINAL)
        self.assertTrue(c.run(0xFFF, 0x0A5, hal.now_us))
        self.assertEqual(hal.q, 0x0A5)
        self.assertTrue(c.run(0x00F, 0x00F, hal.now_us))
        self.assertEqual(hal.q, 0x0AF)
        self.assertEqual(hal.own_req, 0)
        self.assertIsNone(hal.data)  # lines released after the write
        self.assertEqual(c.counters["writes"], 2)

    def test_readback_keeps_the_other_controllers_lines(self):
        hal = ModelHal()
        hal.q = 0x300  # latched by the other controller
        c = Cpdu(hal, REDUNDANT)
        self.assertTrue(c.run(0x001, 0x001, hal.now_us))
        self.assertEqual(hal.q, 0x301)

    def test_busy_and_timeout(self):
        hal = ModelHal()
        c = Cpdu(hal, NOMINAL)
        c.write(1, 1)
        with self.assertRaises(CpduBusyError):
            c.write(1, 0)
        c.reset()
        self.assertEqual(c.state, IDLE)
        hal.other = 1  # the other holds its request: we wait, then give up cleanly
        self.assertFalse(c.run(1, 1, hal.now_us, budget_us=2000))
        self.assertEqual(hal.own_req, 0)
        self.assertEqual(c.counters["aborted"], 2)  # the reset above and the timeout

    def test_battle_priority(self):
        c = Cpdu(ModelHal(), NOMINAL, battle_us=100)
        r = Cpdu(ModelHal(), REDUNDANT, battle_us=100)
        self.assertTrue(c.battle_wait(0) > r.battle_wait(0))  # nominal wins ties
        self.assertTrue(r.battle_wait(1) > c.battle_wait(0))  # a higher priority wins


class TestInterleaved(unittest.TestCase):
    def test_a_million_steps_never_both_inside(self):
        total = 0
        for seed in (1, 2, 3, 4):
            sim = DekkerSim(seed=seed)
            c = sim.run(250000)
            total += c["steps"]
            self.assertEqual(c["both_inside"], 0)
            self.assertEqual(c["collisions"], 0)
            self.assertEqual(c["wrong_latch"], 0)
            self.assertTrue(c["done0"] > 1000 and c["done1"] > 1000)
            self.assertEqual(c["resets0"] + c["resets1"], 0)
        self.assertEqual(total, 1000000)

    def test_contention_produces_battles_both_ways(self):
        sim = DekkerSim(seed=9, start_rate=1, max_dt=60)
        sim.run(100000)
        n, r = sim.ctrl
        self.assertEqual(sim.counters["both_inside"], 0)
        lost = n.counters["battles_lost"] + r.counters["battles_lost"]
        won = n.counters["battles_won"] + r.counters["battles_won"]
        self.assertTrue(lost > 0 and won > 0)
        self.assertTrue(n.counters["waits"] > 0 and r.counters["waits"] > 0)

    def test_settle_shorter_than_rise_is_caught(self):
        # The checker is not blind: without enough settle time mutual exclusion breaks.
        sim = DekkerSim(seed=5, settle_us=5, rise_us=40)
        sim.run(100000)
        self.assertTrue(sim.counters["both_inside"] > 0)


class TestStuck(unittest.TestCase):
    def _stuck(self, who):
        sim = DekkerSim(seed=11 + who, stuck_us=20000, reset_us=5000)
        sim.run(2000)
        sim.stick(who)
        other = 1 - who
        before = sim.counters["done%d" % other]
        sim.run(200000)
        self.assertEqual(sim.counters["resets%d" % who], 1)
        self.assertEqual(sim.counters["resets%d" % other], 0)
        self.assertEqual(sim.counters["both_inside"], 0)
        self.assertTrue(sim.counters["done%d" % other] > before + 100)
        self.assertFalse(sim.stuck[who])
        return sim

    def test_nominal_stuck_redundant_carries_on(self):
        self._stuck(0)

    def test_redundant_stuck_nominal_carries_on(self):
        self._stuck(1)

    def test_hang_inside_is_reset(self):
        sim = DekkerSim(seed=21)
        for _ in range(100000):
            sim.step()
            if sim.ctrl[1].inside:
                break
        self.assertTrue(sim.ctrl[1].inside)
        sim.hang(1)
        sim.run(100000)
        self.assertEqual(sim.counters["resets1"], 1)
        self.assertEqual(sim.counters["both_inside"], 0)
        self.assertTrue(sim.counters["done0"] > 100)
