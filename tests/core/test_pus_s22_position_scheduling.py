"""ST[22]: TCs released when a position parameter reaches their tag; management as ST[11]."""

import unittest

from obsw.pus.parameters import ParameterPool
from obsw.pus.services.s01_verification import FAILURE_REFUSED
from obsw.pus.services.s17_test import ServiceTest
from obsw.pus.services.s22_position_scheduling import PositionScheduling, PositionSchedulingUser
from obsw.store import Store
from pus_loop import APID, Loop, sdb
from store_sim import SimFs


def make(store=None, **options):
    loop = Loop(store=store)
    pool = ParameterPool(sdb())
    pool.values[100] = 10  # "count" plays the distance travelled
    sched = loop.app.register(PositionScheduling(pool, "count", **options))
    loop.app.register(ServiceTest())
    user = loop.ground.register(PositionSchedulingUser())
    return loop, sched, user, pool


def move(loop, pool, position):
    pool.values[100] = position
    loop.clock.advance(0.1)
    loop.app.tick()
    loop.pump()


class TestPositionScheduling(unittest.TestCase):
    def test_release_when_the_position_is_reached(self):
        loop, sched, user, pool = make()
        a = user.embed(APID, 17, 1)[1]
        b = user.embed(APID, 17, 1)[1]
        self.assertTrue(loop.run(user.insert(APID, [(50, a), (30, b)])).ok)
        move(loop, pool, 29)
        self.assertFalse(b.done)
        move(loop, pool, 30)
        self.assertTrue(b.ok)
        move(loop, pool, 49)
        self.assertFalse(a.done)
        move(loop, pool, 75)
        self.assertTrue(a.ok)
        self.assertEqual(sched.released, 2)

    def test_reports_and_position_shifts(self):
        loop, sched, user, pool = make(subschedules=2)
        txs = [user.embed(APID, 17, 1)[1] for _ in range(3)]
        loop.run(user.insert(APID, [(100, txs[0]), (200, txs[1], 1), (300, txs[2])]))
        tx = loop.run(user.detail_all(APID))
        self.assertEqual([a["position"] for a in tx.reply["activities"]], [100, 200, 300])
        self.assertEqual(tx.reply["activities"][1]["subschedule"], 1)
        self.assertTrue(loop.run(user.shift(APID, -20, [txs[0]])).ok)
        self.assertTrue(loop.run(user.shift_filter(APID, 5, start=150, subschedules=[1])).ok)
        self.assertTrue(loop.run(user.shift_all(APID, 1)).ok)
        tx = loop.run(user.summary_all(APID))
        self.assertEqual([a["position"] for a in tx.reply["activities"]], [81, 206, 301])
        tx = loop.run(user.shift_all(APID, -75))  # 81 - 75 is behind the rover (at 10)
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, FAILURE_REFUSED))
        tx = loop.run(user.summary_filter(APID, 200, 400))
        self.assertEqual([a["position"] for a in tx.reply["activities"]], [206, 301])
        self.assertTrue(loop.run(user.delete(APID, [txs[1]])).ok)
        self.assertEqual([a.tag for a in sched.activities], [81, 301])

    def test_insert_behind_the_position_is_refused(self):
        loop, sched, user, pool = make(margin=5)
        for position in (9, 14):
            tx = loop.run(user.insert(APID, [(position, user.embed(APID, 17, 1)[1])]))
            self.assertEqual(tx.failure["code"], FAILURE_REFUSED)
        self.assertTrue(loop.run(user.insert(APID, [(15, user.embed(APID, 17, 1)[1])])).ok)

    def test_groups_subschedules_and_reset(self):
        loop, sched, user, pool = make(subschedules=2)
        self.assertTrue(loop.run(user.create_groups(APID, [5])).ok)
        self.assertTrue(loop.run(user.disable_groups(APID, [5])).ok)
        self.assertTrue(loop.run(user.disable_subschedules(APID, [0])).ok)
        tx = loop.run(user.group_status(APID))
        self.assertEqual(tx.reply["items"], [{"id": 5, "enabled": False}])
        tx = loop.run(user.subschedule_status(APID))
        self.assertEqual([i["enabled"] for i in tx.reply["items"]], [False, True])
        self.assertTrue(loop.run(user.reset(APID)).ok)
        self.assertFalse(sched.enabled)
        self.assertEqual(sched.groups, {})

    def test_restart_keeps_the_schedule(self):
        fs = SimFs()
        loop, sched, user, pool = make(Store("/ctx", fs))
        a = user.embed(APID, 17, 1)[1]
        loop.run(user.insert(APID, [(40, a)]))
        loop2, sched2, _, pool2 = make(Store("/ctx", fs))
        loop2.ground = loop.ground
        move(loop2, pool2, 39)
        self.assertFalse(a.done)
        move(loop2, pool2, 40)
        self.assertTrue(a.ok)


if __name__ == "__main__":
    unittest.main()
