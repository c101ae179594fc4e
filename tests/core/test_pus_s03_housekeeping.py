"""ST[03]: every request, provider against user, periodic generation, persisted context."""

import unittest

from obsw.pus.parameters import ParameterPool
from obsw.pus.services.s01_verification import (
    FAILURE_EXECUTION,
    FAILURE_REFUSED,
    FAILURE_UNKNOWN_ID,
)
from obsw.pus.services.s03_housekeeping import Housekeeping, HousekeepingUser
from obsw.store import Store
from pus_loop import APID, Loop, sdb
from store_sim import SimFs


def make(store=None):
    db = sdb()
    loop = Loop(store=store)
    pool = ParameterPool(db)
    pool.values.update({1: 12.5, 2: 3.0, 3: 2, 4: True, 5: "panel"})
    hk = loop.app.register(Housekeeping(pool, db.housekeeping))
    user = loop.ground.register(
        HousekeepingUser(
            lambda pid: db.parameter(pid).type,
            lambda pid: db.parameter(pid).qualified,
            db.housekeeping,
        )
    )
    return loop, hk, user, pool


class TestHousekeeping(unittest.TestCase):
    def test_one_shot_report(self):
        loop, hk, user, pool = make()
        tx = loop.run(user.one_shot(APID, [1]))
        self.assertTrue(tx.ok)
        self.assertEqual(
            tx.reply,
            {"sid": 1, "values": {"Panel.angle": 12.5, "Panel.speed": 3.0, "Panel.mode": 2}},
        )
        self.assertEqual(loop.types(), [(1, 1), (1, 3), (3, 25), (1, 7)])

    def test_create_report_structures_and_delete(self):
        loop, hk, user, pool = make()
        tx = loop.run(user.create(APID, 7, 3, [4, 5, 100]))
        self.assertTrue(tx.ok)
        tx = loop.run(user.report_structures(APID, [7, 1]))
        self.assertEqual(len(tx.replies), 2)
        self.assertEqual(
            tx.replies[0],
            {"sid": 7, "enabled": False, "interval": 3, "parameters": [4, 5, 100], "groups": []},
        )
        self.assertEqual(tx.replies[1]["parameters"], [1, 2, 3])
        tx = loop.run(user.one_shot(APID, [7]))
        self.assertEqual(
            tx.reply["values"], {"Panel.deployed": True, "Panel.label": "panel", "count": 0}
        )
        tx = loop.run(user.delete(APID, [7]))
        self.assertTrue(tx.ok)
        self.assertEqual(sorted(hk.structures), [1])

    def test_create_refusals(self):
        loop, hk, user, pool = make()
        for sid, interval, pids, code in (
            (1, 3, [1], FAILURE_REFUSED),  # in use
            (8, 0, [1], FAILURE_REFUSED),  # interval 0
            (8, 1, [1, 999], FAILURE_UNKNOWN_ID),
        ):
            tx = loop.run(user.create(APID, sid, interval, pids))
            self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, code))
        self.assertEqual(sorted(hk.structures), [1])

    def test_enable_disable_and_periodic_reports(self):
        loop, hk, user, pool = make()
        self.assertTrue(loop.run(user.enable(APID, [1])).ok)
        for _ in range(6):
            loop.app.tick()
        loop.pump()
        reports = loop.unsolicited(3, 25)
        self.assertEqual(len(reports), 3)  # every 2 cycles
        pool.values[1] = -4.0
        loop.app.tick()
        loop.app.tick()
        loop.pump()
        self.assertEqual(loop.unsolicited(3, 25)[-1]["values"]["Panel.angle"], -4.0)
        self.assertTrue(loop.run(user.modify_interval(APID, {1: 4})).ok)
        tx = loop.run(user.report_properties(APID, [1]))
        self.assertEqual(tx.reply, {"items": [{"sid": 1, "enabled": True, "interval": 4}]})
        before = len(loop.unsolicited(3, 25))
        for _ in range(8):
            loop.app.tick()
        loop.pump()
        self.assertEqual(len(loop.unsolicited(3, 25)) - before, 2)
        tx = loop.run(user.delete(APID, [1]))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)  # still enabled
        self.assertTrue(loop.run(user.disable(APID, [1])).ok)
        before = len(loop.unsolicited(3, 25))
        for _ in range(8):
            loop.app.tick()
        loop.pump()
        self.assertEqual(len(loop.unsolicited(3, 25)), before)

    def test_unknown_structures(self):
        loop, hk, user, pool = make()
        for tx in (
            user.delete(APID, [9]),
            user.enable(APID, [1, 9]),
            user.disable(APID, [9]),
            user.one_shot(APID, [9]),
            user.report_structures(APID, [9]),
            user.modify_interval(APID, {9: 2}),
            user.report_properties(APID, [9]),
        ):
            loop.run(tx)
            self.assertEqual(
                (tx.failure["code"], tx.failure["data"]), (FAILURE_UNKNOWN_ID, b"\x00\x09")
            )
        self.assertFalse(hk.structures[1].enabled)

    def test_report_of_an_unknown_structure_stays_raw(self):
        loop, hk, user, pool = make()
        user.structures.clear()
        tx = loop.run(user.one_shot(APID, [1]))
        self.assertEqual(tx.reply["sid"], 1)
        self.assertEqual(len(tx.reply["raw"]), 9)

    def test_context_survives_a_restart(self):
        fs = SimFs()
        loop, hk, user, pool = make(Store("/ctx", fs))
        loop.run(user.create(APID, 5, 7, [2]))
        loop.run(user.enable(APID, [5]))
        loop.run(user.modify_interval(APID, {5: 9}))
        loop2, hk2, user2, pool2 = make(Store("/ctx", fs))
        self.assertEqual(sorted(hk2.structures), [1, 5])
        s = hk2.structures[5]
        self.assertEqual((s.interval, s.parameters, s.enabled), (9, [2], True))

    def test_broken_context_is_ignored(self):
        fs = SimFs()
        Store("/ctx", fs).save("s03", [[5, 1, [999], True]])
        loop, hk, user, pool = make(Store("/ctx", fs))
        self.assertEqual(sorted(hk.structures), [1])
        self.assertEqual(loop.app.counters["context_rejected"], 1)


if __name__ == "__main__":
    unittest.main()


class TestUnsent(unittest.TestCase):
    """A report that cannot be built is heard with its reason; the counts do not skip."""

    def test_a_value_the_structure_cannot_carry_names_the_parameter(self):
        loop, hk, user, pool = make()
        heard = []
        loop.app.unsent_listeners.append(lambda *a: heard.append(a))
        count = loop.app.sequence.peek(APID)
        pool.values[3] = 70000  # Panel.mode is a uint8
        self.assertIsNone(hk.generate(1))
        self.assertEqual(len(heard), 1)
        service, subtype, why = heard[0]
        self.assertEqual((service, subtype), (3, 25))
        self.assertTrue(why.startswith("structure 1: parameter 3 = 70000: "), why)
        self.assertEqual(loop.app.counters.get("hk_unpackable"), 1)
        self.assertEqual(loop.app.sequence.peek(APID), count)

    def test_a_one_shot_report_that_cannot_be_built_fails_its_request(self):
        loop, hk, user, pool = make()
        heard = []
        loop.app.unsent_listeners.append(lambda *a: heard.append(a))
        pool.values[3] = 70000  # Panel.mode is a uint8
        tx = loop.run(user.one_shot(APID, [1]))
        self.assertFalse(tx.ok)
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (4, FAILURE_EXECUTION))
        self.assertEqual(bytes(tx.failure["data"]), b"\x00\x01")
        self.assertEqual([h[:2] for h in heard], [(3, 25)])
        self.assertTrue((3, 25) not in loop.types())

    def test_an_output_that_fails_is_heard(self):
        loop, hk, user, pool = make()
        heard = []
        loop.app.unsent_listeners.append(lambda *a: heard.append(a))

        def broken(raw):
            raise OSError("message too long")

        loop.app.out = broken
        self.assertIsNone(hk.generate(1))
        self.assertEqual(heard, [(3, 25, "output failed: message too long")])

    def test_a_packet_too_long_is_heard_and_leaves_no_gap(self):
        loop, hk, user, pool = make()
        heard = []
        loop.app.unsent_listeners.append(lambda *a: heard.append(a))
        count = loop.app.sequence.peek(APID)
        self.assertIsNone(loop.app.send_tm(3, 25, bytes(70000)))
        self.assertEqual([h[:2] for h in heard], [(3, 25)])
        self.assertTrue("70" in heard[0][2], heard)
        self.assertEqual(loop.app.sequence.peek(APID), count)
        self.assertIsNotNone(loop.app.send_tm(3, 25, b"\x00\x01"))
        self.assertEqual(loop.app.sequence.peek(APID), count + 1)
