"""The parameter pool follows components that start after it and components that restart:
each is subscribed again when it appears and its values are read again (issue 23)."""

import unittest

from obsw.il.clock import SimClock
from obsw.il.interface import CONFIGURATION, DATA, INFO, Attribute, Event, Interface
from obsw.il.loopback import resolver_for
from obsw.il.node import Node
from obsw.pus.events import EventManager
from obsw.pus.parameters import ParameterPool
from pus_loop import sdb

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
    ],
)


class Panel:
    def __init__(self, angle):
        self.angle = angle
        self.speed = 2.0
        self.mode = 0
        self.deployed = False
        self.label = "p"
        self.il = None

    def il_bind(self, provider):
        self.il = provider


class TestFollow(unittest.TestCase):
    """The pool's node (the PUS process) and a component's node (its own process), joined by
    loopback links that encode every message as CBOR, as sockets would."""

    def setUp(self):
        self.clock = SimClock()
        self.pus = Node("pus", self.clock)
        self.others = []
        self.pus.registry.resolver = resolver_for(self.pus, lambda: self.others, codec=True)
        self.pool = ParameterPool(sdb(), self.pus, timeout=0.5)
        self.events = EventManager(sdb(), self.pus)
        self.raised = []
        self.events.listeners.append(lambda *e: self.raised.append(e[0]))

    def start_component(self, angle):
        """A new 'process' providing the panel (the old one, if any, is gone)."""
        for route in list(self.pus.registry._routes.values()):
            if not route.local:
                route.cut()
        node = Node("panel-%d" % len(self.others), self.clock)
        panel = Panel(angle)
        provider = node.provide(PANEL, panel)
        self.others = [node]
        return provider

    def test_component_that_starts_after_the_pool(self):
        self.assertEqual(self.pool.bind(), 0)
        self.events.bind()
        self.assertEqual(len(self.pool.unbound), 5)
        self.assertEqual(self.pool.get(1), 0.0)  # not there: the type's zero
        provider = self.start_component(12.5)
        self.assertEqual(self.pool.refresh(), 5)  # it appeared: read
        self.assertEqual(self.pool.unbound, [])
        self.assertEqual(self.pool.get(1), 12.5)
        provider.update("angle", 13.0)  # and subscribed: publications come
        self.pus.poll()
        self.assertEqual(self.pool.get(1), 13.0)
        provider.emit("moved", {"angle": 13.0})
        self.pus.poll()
        self.assertEqual(len(self.raised), 1)
        self.assertEqual(self.pool.refresh(), 0)  # nothing new: nothing read

    def test_component_that_restarts(self):
        provider = self.start_component(1.0)
        self.assertEqual(self.pool.bind(), 5)
        self.events.bind()
        provider.update("angle", 40.0)
        self.pus.poll()
        self.assertEqual(self.pool.get(1), 40.0)
        provider = self.start_component(3.0)  # restarted: its state is new
        self.assertEqual(self.pool.refresh(), 5)
        self.assertEqual(self.pool.get(1), 3.0)
        provider.update("angle", 4.0)  # the subscription was renewed
        self.pus.poll()
        self.assertEqual(self.pool.get(1), 4.0)
        provider.emit("moved", {"angle": 4.0})
        self.pus.poll()
        self.assertEqual(len(self.raised), 1)

    def test_component_gone_is_unbound_until_it_returns(self):
        self.start_component(1.0)
        self.pool.bind()
        for route in list(self.pus.registry._routes.values()):
            route.cut()
        self.others = []
        self.assertEqual(self.pool.refresh(), 0)
        self.assertEqual(len(self.pool.unbound), 5)
        self.assertEqual(self.pool.get(1), 1.0)  # the last known value stays meanwhile
        self.start_component(7.0)
        self.assertEqual(self.pool.refresh(), 5)
        self.assertEqual(self.pool.get(1), 7.0)


if __name__ == "__main__":
    unittest.main()
