"""ST[22] TC[22,28] set the orbit number: the position parameter is set, through its component
when it has one, and activities the new position has reached are released."""

import unittest

from obsw.il.errors import UnavailableError
from obsw.pus.messages import FAILURE_REFUSED, FAILURE_UNAVAILABLE
from obsw.pus.parameters import ParameterPool
from obsw.pus.sdb import loads
from obsw.pus.services.base import PARAMETER_ID
from obsw.pus.services.s17_test import ServiceTest
from obsw.pus.services.s22_position_scheduling import (
    ORBIT,
    PositionScheduling,
    PositionSchedulingUser,
)
from pus_loop import APID, Loop

SDB = """{
  "apids": {"pus": 10},
  "components": [{"name": "Orbit", "attributes": [
    {"name": "number", "parameter": 7, "type": "uint16", "writable": true}]}],
  "parameters": [
    {"name": "orbit", "id": 100, "type": "uint32", "writable": true},
    {"name": "odometer", "id": 101, "type": "uint32"}
  ]
}"""


class Node:
    """The part of an interaction layer node a pool sets values through."""

    def __init__(self, fail=False):
        self.fail = fail
        self.sets = []

    async def aset(self, name, value, timeout=None):
        if self.fail:
            raise UnavailableError("no provider of %s" % name, name)
        self.sets.append((name, value))


def make(parameter, node=None):
    loop = Loop()
    pool = ParameterPool(loads(SDB))
    pool.node = node
    sched = loop.app.register(PositionScheduling(pool, parameter))
    loop.app.register(ServiceTest())
    user = loop.ground.register(PositionSchedulingUser())
    return loop, sched, user, pool


class TestSetOrbitNumber(unittest.TestCase):
    def test_sets_the_position_and_releases_what_it_reached(self):
        loop, sched, user, pool = make("orbit")
        a = user.embed(APID, 17, 1)[1]
        b = user.embed(APID, 17, 1)[1]
        self.assertTrue(loop.run(user.insert(APID, [(5000, a), (7000, b)])).ok)
        tx = loop.run(user.set_orbit(APID, 6000))
        self.assertTrue(tx.ok)
        self.assertEqual(pool.get(100), 6000)
        self.assertFalse(a.done)  # released on the next cycle
        loop.app.tick()
        loop.pump()
        self.assertEqual((a.ok, b.done), (True, False))
        self.assertEqual(tx.tc.data, ORBIT.pack({"orbit": 6000}))
        self.assertEqual(tx.tc.data, b"\x00\x00\x17\x70")

    def test_read_only_and_out_of_range_are_refused(self):
        loop, sched, user, pool = make("odometer")
        tx = loop.run(user.set_orbit(APID, 3))
        self.assertEqual(
            (tx.failure["stage"], tx.failure["code"], tx.failure["data"]),
            (2, FAILURE_REFUSED, PARAMETER_ID.pack(101)),
        )
        loop, sched, user, pool = make("Orbit.number")
        tx = loop.run(user.set_orbit(APID, 70000))  # a uint16 parameter
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, FAILURE_REFUSED))

    def test_through_the_component(self):
        node = Node()
        loop, sched, user, pool = make("Orbit.number", node)
        tx = loop.run_async(lambda: user.set_orbit(APID, 12))
        self.assertTrue(tx.ok)
        self.assertEqual(node.sets, [("Orbit.number", 12)])
        self.assertEqual(pool.get(7), 12)
        node.fail = True
        tx = loop.run_async(lambda: user.set_orbit(APID, 13))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (4, FAILURE_UNAVAILABLE))
        self.assertEqual(pool.get(7), 12)


if __name__ == "__main__":
    unittest.main()
