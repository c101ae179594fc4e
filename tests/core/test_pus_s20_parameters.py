"""ST[20]: report and set parameter values, provider against user."""

import unittest

from obsw.pus.parameters import ParameterPool
from obsw.pus.services.s01_verification import FAILURE_REFUSED, FAILURE_UNKNOWN_ID
from obsw.pus.services.s20_parameters import ParameterManagement, ParameterUser
from pus_loop import APID, Loop, sdb


def make():
    db = sdb()
    loop = Loop()
    pool = ParameterPool(db)
    pool.values.update({1: 12.5, 2: 3.0, 3: 2})
    counter = [41]
    pool.provide("count", lambda: counter[0])
    loop.app.register(ParameterManagement(pool))
    user = loop.ground.register(
        ParameterUser(
            lambda pid: db.parameter(pid).type,
            lambda pid: db.parameter(pid).qualified,
            lambda key: db.parameter(key).id,
        )
    )
    return loop, pool, user


class TestParameters(unittest.TestCase):
    def test_report_values(self):
        loop, pool, user = make()
        tx = loop.run(
            user.report(
                APID, ["Panel.angle", 2, "Panel.mode", "Panel.deployed", "Panel.label", "count"]
            )
        )
        self.assertTrue(tx.ok)
        self.assertEqual(
            tx.reply["values"],
            {
                "Panel.angle": 12.5,
                "Panel.speed": 3.0,
                "Panel.mode": 2,
                "Panel.deployed": False,
                "Panel.label": "",
                "count": 41,
            },
        )
        self.assertEqual(loop.types(), [(1, 1), (1, 3), (20, 2), (1, 7)])

    def test_report_unknown_parameter(self):
        loop, pool, user = make()
        tx = loop.run(user.report(APID, [1, 999]))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, FAILURE_UNKNOWN_ID))
        self.assertEqual(tx.failure["data"], b"\x03\xe7")

    def test_set_values(self):
        loop, pool, user = make()
        tx = loop.run_async(
            lambda: user.set(APID, {"Panel.speed": 7.25, "Panel.mode": 9, "Panel.label": "east"})
        )
        self.assertTrue(tx.ok)
        self.assertEqual((pool.get(2), pool.get(3), pool.get(5)), (7.25, 9, "east"))
        tx = loop.run(user.report(APID, ["Panel.speed", "Panel.label"]))
        self.assertEqual(tx.reply["values"], {"Panel.speed": 7.25, "Panel.label": "east"})

    def test_set_read_only_is_refused(self):
        loop, pool, user = make()
        tx = loop.run_async(lambda: user.set(APID, {"Panel.mode": 1, "Panel.angle": 1.0}))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, FAILURE_REFUSED))
        self.assertEqual(pool.get(3), 2)  # nothing changed

    def test_set_unknown_parameter_fails_acceptance(self):
        loop, pool, user = make()
        tx = loop.run_async(lambda: loop.ground.send(APID, 20, 3, b"\x01\x03\xe7\x00"))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (1, 5))


if __name__ == "__main__":
    unittest.main()
