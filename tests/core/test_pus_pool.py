"""Parameter pool and event manager on an interaction layer node, through service 20 and 5."""

import unittest

from obsw.il.errors import ComponentError
from obsw.il.interface import CONFIGURATION, DATA, HIGH, INFO, Attribute, Event, Interface
from obsw.il.node import Node
from obsw.pus.events import EventManager
from obsw.pus.parameters import ParameterError, ParameterPool
from obsw.pus.services.s01_verification import FAILURE_COMPONENT
from obsw.pus.services.s05_events import EventReporting, EventUser
from obsw.pus.services.s20_parameters import ParameterManagement, ParameterUser
from pus_loop import APID, Loop, sdb

PANEL = Interface(
    "Panel",
    1,
    [
        Attribute("angle", 1, DATA),
        Attribute("speed", 2, CONFIGURATION),
        Attribute("mode", 3, CONFIGURATION),
        Attribute("deployed", 4, DATA),
        Attribute("label", 5, CONFIGURATION),
        Event("moved", 6, INFO),
        Event("stuck", 7, HIGH),
    ],
)


class Panel:
    def __init__(self):
        self.angle = 1.0
        self._speed = 2.0
        self.mode = 0
        self.deployed = False
        self.label = "p"
        self.il = None

    def il_bind(self, provider):
        self.il = provider

    @property
    def speed(self):
        return self._speed

    @speed.setter
    def speed(self, value):
        if value > 10:
            raise ComponentError("TOO_FAST", "speed above 10")
        self._speed = value


def make():
    db = sdb()
    node = Node("pus")
    panel = Panel()
    provider = node.provide(PANEL, panel)
    loop = Loop()
    pool = ParameterPool(db, node)
    events = EventManager(db, node)
    events.connect(loop.app)
    pool.bind()
    events.bind()
    loop.app.register(ParameterManagement(pool))
    loop.app.register(EventReporting())
    types = lambda pid: db.parameter(pid).type  # noqa: E731
    names = lambda pid: db.parameter(pid).qualified  # noqa: E731
    user = loop.ground.register(ParameterUser(types, names, lambda k: db.parameter(k).id))
    loop.ground.register(EventUser(db.event))
    return loop, node, panel, provider, pool, events, user


class TestPool(unittest.TestCase):
    def test_bind_reads_current_values(self):
        loop, node, panel, provider, pool, events, user = make()
        self.assertEqual(pool.unbound, [])
        self.assertEqual((pool.get(1), pool.get(2), pool.get(5)), (1.0, 2.0, "p"))
        self.assertEqual(pool.get(100), 0)  # no component, no getter: zero of its type

    def test_publications_refresh_the_cache(self):
        loop, node, panel, provider, pool, events, user = make()
        provider.update("angle", 33.0)
        node.poll()
        self.assertEqual(pool.get(1), 33.0)
        tx = loop.run(user.report(APID, ["Panel.angle"]))
        self.assertEqual(tx.reply["values"], {"Panel.angle": 33.0})

    def test_set_through_the_component(self):
        loop, node, panel, provider, pool, events, user = make()
        tx = loop.run_async(lambda: user.set(APID, {"Panel.speed": 4.0, "Panel.mode": 3}))
        self.assertTrue(tx.ok)
        self.assertEqual((panel.speed, panel.mode), (4.0, 3))
        node.poll()
        self.assertEqual(pool.get(2), 4.0)

    def test_component_refusal_fails_completion(self):
        loop, node, panel, provider, pool, events, user = make()
        tx = loop.run_async(lambda: user.set(APID, {"Panel.speed": 50.0}))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (4, FAILURE_COMPONENT))
        self.assertEqual(panel.speed, 2.0)

    def test_plain_set_checks(self):
        loop, node, panel, provider, pool, events, user = make()
        pool.set(3, 7)
        self.assertEqual(panel.mode, 7)
        self.assertRaises(ParameterError, pool.set, 1, 2.0)  # read-only
        self.assertRaises(ParameterError, pool.set, 999, 2.0)
        self.assertRaises(ValueError, pool.set, 3, 300)  # does not fit uint8

    def test_unbound_component(self):
        db = sdb()
        pool = ParameterPool(db, Node("empty"), timeout=0)
        pool.bind()
        self.assertEqual(len(pool.unbound), 5)

    def test_component_events_become_pus_events(self):
        loop, node, panel, provider, pool, events, user = make()
        provider.emit("moved", {"angle": 2.5})
        provider.emit("stuck", {"code": 3})
        node.poll()
        loop.pump()
        self.assertEqual(loop.types(), [(5, 1), (5, 4)])
        self.assertEqual(loop.results[0][1]["data"], {"angle": 2.5})
        self.assertEqual(loop.results[1][1]["event"], "Panel.stuck")
        events.close()
        pool.close()
        provider.emit("moved", {"angle": 1.0})
        node.poll()
        loop.pump()
        self.assertEqual(len(loop.tm), 2)


if __name__ == "__main__":
    unittest.main()


class TestDefaults(unittest.TestCase):
    """A parameter's ``default`` is an engineering value (as its range is): the pool gives
    its raw value until the parameter has one of its own."""

    def test_a_default_is_turned_raw(self):
        from obsw.pus.sdb import loads

        db = loads(
            '{"mission": "m", "parameters": ['
            '{"name": "t", "id": 1, "type": "uint16", "default": 20, '
            '"calibration": {"spline": [[1365, 0], [1765, 100]]}},'
            '{"name": "m", "id": 2, "type": "uint8", "default": "POINTING", '
            '"enumeration": {"0": "OFF", "2": "POINTING"}},'
            '{"name": "g", "id": 3, "type": "int32", "default": 250}]}'
        )
        pool = ParameterPool(db)
        self.assertEqual(pool.get(1), 1365 + 4 * 20)
        self.assertEqual(pool.get(2), 2)
        self.assertEqual(pool.get(3), 250)
        pool.values[1] = 1500
        self.assertEqual(pool.get(1), 1500)
