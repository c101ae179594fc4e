"""ST[04]: parameter statistics over an interval, on request and periodic, provider against
user; definitions survive a restart."""

import unittest

from obsw.pus.messages import FAILURE_REFUSED, FAILURE_UNKNOWN_ID
from obsw.pus.parameters import ParameterPool
from obsw.pus.services.s04_statistics import ParameterStatistics, StatisticsUser
from obsw.store import Store
from pus_loop import APID, Loop, sdb
from store_sim import SimFs


def make(store=None):
    db = sdb()
    loop = Loop(store=store)
    pool = ParameterPool(db)
    stats = loop.app.register(ParameterStatistics(pool))
    user = loop.ground.register(
        StatisticsUser(
            lambda pid: db.parameter(pid).type,
            lambda pid: db.parameter(pid).qualified,
            lambda key: db.parameter(key).id,
        )
    )
    return loop, pool, stats, user


def feed(loop, pool, pid, values):
    for v in values:
        pool.values[pid] = v
        loop.clock.advance(1.0)
        loop.app.tick()


class TestStatistics(unittest.TestCase):
    def test_report_on_request_with_reset(self):
        loop, pool, stats, user = make()
        self.assertTrue(
            loop.run(user.add_definitions(APID, {"Panel.angle": 1, "Panel.mode": 2})).ok
        )
        feed(loop, pool, 1, [2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0])
        pool.values[3] = 3
        tx = loop.run(user.report(APID, reset=True))
        self.assertTrue(tx.ok)
        r = tx.reply
        self.assertEqual((r["start"], r["end"]), (1000.0, 1008.0))
        a = r["statistics"]["Panel.angle"]
        self.assertEqual((a["samples"], a["min"], a["max"]), (8, 2.0, 9.0))
        self.assertEqual((a["min_time"], a["max_time"]), (1001.0, 1008.0))
        self.assertAlmostEqual(a["mean"], 5.0)
        self.assertAlmostEqual(a["stddev"], 2.0)
        m = r["statistics"]["Panel.mode"]
        self.assertEqual((m["samples"], m["min"], m["max"]), (4, 0, 0))  # every 2nd cycle
        tx = loop.run(user.report(APID))
        a = tx.reply["statistics"]["Panel.angle"]
        self.assertEqual((a["samples"], a["mean"], a["stddev"]), (0, 0.0, 0.0))
        self.assertEqual(tx.reply["start"], 1008.0)

    def test_reset_and_periodic_reports(self):
        loop, pool, stats, user = make()
        loop.run(user.add_definitions(APID, {1: 1}))
        feed(loop, pool, 1, [1.0, 3.0])
        self.assertTrue(loop.run(user.reset(APID)).ok)
        self.assertEqual(stats.stats[1].n, 0)
        self.assertTrue(loop.run(user.enable_periodic(APID, 3)).ok)
        feed(loop, pool, 1, [10.0, 20.0, 30.0, 40.0, 50.0, 60.0])
        loop.pump()
        reports = loop.unsolicited(4, 2)
        self.assertEqual(len(reports), 2)
        self.assertEqual([r["statistics"]["Panel.angle"]["mean"] for r in reports], [20.0, 50.0])
        self.assertEqual(reports[1]["statistics"]["Panel.angle"]["samples"], 3)
        tx = loop.run(user.report_definitions(APID))
        self.assertEqual(tx.reply, {"interval": 3, "items": {"Panel.angle": 1}})
        self.assertTrue(loop.run(user.disable_periodic(APID)).ok)
        feed(loop, pool, 1, [1.0] * 6)
        loop.pump()
        self.assertEqual(len(loop.unsolicited(4, 2)), 2)
        self.assertEqual(loop.run(user.report_definitions(APID)).reply["interval"], 0)
        tx = loop.run(user.enable_periodic(APID, 0))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)

    def test_definitions(self):
        loop, pool, stats, user = make()
        for defs, code in (({999: 1}, FAILURE_UNKNOWN_ID), ({"Panel.label": 1}, FAILURE_REFUSED)):
            tx = loop.run(user.add_definitions(APID, defs))
            self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, code))
        loop.run(user.add_definitions(APID, {1: 1, 2: 5}))
        loop.run(user.add_definitions(APID, {2: 2}))  # an update
        self.assertEqual(stats.stats[2].interval, 2)
        tx = loop.run(user.delete_definitions(APID, [3]))
        self.assertEqual(tx.failure["code"], FAILURE_UNKNOWN_ID)
        self.assertTrue(loop.run(user.delete_definitions(APID, [1])).ok)
        self.assertEqual(sorted(stats.stats), [2])
        self.assertTrue(loop.run(user.delete_definitions(APID)).ok)
        self.assertEqual(stats.stats, {})
        stats.max_definitions = 1
        tx = loop.run(user.add_definitions(APID, {1: 1, 2: 1}))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)

    def test_definitions_survive_a_restart(self):
        fs = SimFs()
        loop, pool, stats, user = make(Store("/ctx", fs))
        loop.run(user.add_definitions(APID, {1: 4, 2: 1}))
        loop.run(user.enable_periodic(APID, 7))
        loop2, pool2, stats2, user2 = make(Store("/ctx", fs))
        self.assertEqual({p: s.interval for p, s in stats2.stats.items()}, {1: 4, 2: 1})
        self.assertEqual((stats2.periodic, stats2.reporting_interval), (True, 7))


if __name__ == "__main__":
    unittest.main()
