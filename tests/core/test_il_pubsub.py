"""Publish/subscribe: attribute updates and events, queue policies, callbacks, fan-out and
subscriptions across a (loopback) process boundary that survive a provider restart."""

import unittest

from obsw.il.clock import SimClock
from obsw.il.errors import UnavailableError, UnknownMemberError
from obsw.il.interface import CONFIGURATION, DATA, Attribute, Event, Interface, Operation
from obsw.il.loopback import resolver_for
from obsw.il.message import Publication
from obsw.il.node import Node
from obsw.il.queue import DROP_NEWEST, EMPTY, Queue

THERMO = Interface(
    "Thermometer",
    0x20,
    [
        Attribute("temperature", 1, DATA, unit="degC"),
        Attribute("limit", 2, CONFIGURATION, unit="degC"),
        Operation("sample", 3, ("value",)),
        Event("over_limit", 4),
        Event("dump", 5),
    ],
)


class Thermometer:
    def __init__(self):
        self.temperature = 20
        self.limit = 40

    def il_bind(self, provider):
        self.il = provider

    def sample(self, value):
        self.il.update("temperature", value)
        if value > self.limit:
            self.il.emit("over_limit", {"value": value, "limit": self.limit})
        return value


class Setup(unittest.TestCase):
    def setUp(self):
        self.clock = SimClock()
        self.node = Node("obc", self.clock)
        self.thermo = Thermometer()
        self.provider = self.node.provide(THERMO, self.thermo)
        self.proxy = self.node.proxy(THERMO, timeout=1.0)


class TestLocal(Setup):
    def test_attribute_updates_and_events(self):
        temps = self.proxy.subscribe("temperature")
        alarms = self.proxy.subscribe("over_limit")
        self.proxy.sample(30)
        self.proxy.sample(50)
        self.assertEqual(temps.receive().value, 30)
        self.assertEqual(temps.receive().value, 50)
        self.assertIs(temps.receive(), EMPTY)
        pub = alarms.receive()
        self.assertEqual(pub, Publication("Thermometer", "over_limit", {"value": 50, "limit": 40}))
        self.assertEqual(pub.name, "Thermometer.over_limit")

    def test_set_publishes_the_new_value(self):
        limits = self.node.subscribe("Thermometer.limit", timeout=1)
        self.proxy.set("limit", 60)
        self.assertEqual(limits.receive().value, 60)

    def test_wildcard(self):
        everything = self.proxy.subscribe("*", length=8)
        self.proxy.sample(45)
        names = []
        while True:
            pub = everything.receive()
            if pub is EMPTY:
                break
            names.append(pub.member)
        self.assertEqual(names, ["temperature", "over_limit"])

    def test_fan_out_to_many_subscribers(self):
        subs = [self.proxy.subscribe("temperature") for _ in range(10)]
        self.assertEqual(self.node.publish("Thermometer", "temperature", 1), 10)
        self.assertEqual([s.receive().value for s in subs], [1] * 10)

    def test_overwrite_oldest_default_counts_drops(self):
        sub = self.proxy.subscribe("temperature", length=2)
        for v in range(5):
            self.proxy.sample(v)
        self.assertEqual([sub.receive().value, sub.receive().value], [3, 4])
        self.assertEqual(sub.dropped, 3)

    def test_own_queue_with_drop_newest(self):
        q = Queue(1, DROP_NEWEST, copy=False)
        sub = self.proxy.subscribe("temperature", queue=q)
        self.proxy.sample(1)
        self.proxy.sample(2)
        self.assertEqual(sub.receive().value, 1)
        self.assertEqual(q.dropped, 1)

    def test_callbacks_run_from_poll(self):
        seen = []
        self.proxy.subscribe("temperature", lambda pub: seen.append(pub.value))
        self.proxy.sample(5)
        self.assertEqual(seen, [])
        self.assertEqual(self.node.poll(), 1)
        self.assertEqual(seen, [5])

    def test_blocking_receive_waits_on_the_clock(self):
        sub = self.proxy.subscribe("temperature")
        self.clock.call_at(2.0, lambda: self.thermo.sample(33))
        self.assertIs(sub.receive(timeout=1.0), EMPTY)
        self.assertEqual(sub.receive(timeout=5.0).value, 33)
        self.assertEqual(self.clock.now(), 2.0)

    def test_cancel(self):
        sub = self.proxy.subscribe("temperature")
        sub.cancel()
        self.proxy.sample(1)
        self.assertIs(sub.receive(), EMPTY)
        self.assertEqual(self.node.publish("Thermometer", "temperature", 2), 0)

    def test_cannot_subscribe_to_operation_or_unknown(self):
        with self.assertRaises(UnknownMemberError):
            self.proxy.subscribe("sample")
        with self.assertRaises(UnknownMemberError):
            self.proxy.subscribe("humidity")
        with self.assertRaises(UnavailableError):
            self.node.subscribe("Nobody.x", timeout=0.1)

    def test_large_event_payload(self):
        sub = self.proxy.subscribe("dump")
        blob = bytes(range(256)) * 64
        self.provider.emit("dump", {"image": blob, 1: [blob]})
        self.assertIs(sub.receive().value["image"], blob)

    def test_emit_unknown_event(self):
        with self.assertRaises(UnknownMemberError):
            self.provider.emit("sample", 1)
        with self.assertRaises(UnknownMemberError):
            self.provider.update("over_limit", 1)


class TestAcrossNodes(unittest.TestCase):
    """Two nodes joined by loopback links that encode every message as CBOR."""

    def setUp(self):
        self.clock = SimClock()
        self.provider_node = Node("sensor", self.clock)
        self.user = Node("user", self.clock)
        nodes = lambda: [self.provider_node, self.user]  # noqa: E731
        self.user.registry.resolver = resolver_for(self.user, nodes, codec=True)
        self.thermo = Thermometer()
        self.provider = self.provider_node.provide(THERMO, self.thermo)
        self.proxy = self.user.proxy(THERMO, timeout=1.0)

    def restart(self):
        """Kill the provider's 'process' and start a new one."""
        for route in list(self.user.registry._routes.values()):
            if not route.local:
                route.cut()
        self.provider_node.withdraw(self.provider)
        self.provider_node = Node("sensor2", self.clock)
        self.thermo = Thermometer()
        self.provider = self.provider_node.provide(THERMO, self.thermo)

    def test_call_and_publication_cross(self):
        sub = self.proxy.subscribe("over_limit")
        self.assertEqual(self.proxy.sample(99), 99)
        self.assertEqual(sub.receive().value, {"value": 99, "limit": 40})
        self.assertEqual(self.proxy.temperature, 99)

    def test_one_wire_subscription_per_topic(self):
        a = self.proxy.subscribe("temperature")
        b = self.proxy.subscribe("temperature")
        self.assertEqual(len(self.provider_node._subs[("Thermometer", "temperature")]), 1)
        self.thermo.sample(3)
        self.assertEqual((a.receive().value, b.receive().value), (3, 3))
        a.cancel()
        self.assertEqual(len(self.provider_node._subs[("Thermometer", "temperature")]), 1)
        b.cancel()
        self.assertEqual(len(self.provider_node._subs[("Thermometer", "temperature")]), 0)

    def test_subscription_survives_restart(self):
        sub = self.proxy.subscribe("temperature")
        self.restart()
        self.assertEqual(self.proxy.sample(21), 21)  # the call finds the new provider
        self.assertEqual(sub.receive().value, 21)  # and the subscription was renewed

    def test_call_in_flight_is_sent_again_to_the_restarted_provider(self):
        test = self

        class Crashing(Thermometer):
            def sample(self, value):  # the process dies while serving the call
                for route in list(test.user.registry._routes.values()):
                    if not route.local:
                        route.cut()
                test.provider_node.withdraw(test.provider)
                test.clock.call_later(0.2, test.start_new)
                return value

        self.provider_node.withdraw(self.provider)
        self.provider = self.provider_node.provide(THERMO, Crashing())
        self.assertEqual(self.user.call("Thermometer.sample", (5,), timeout=1.0), 5)
        self.assertAlmostEqual(self.clock.now(), 0.2)
        self.assertEqual(self.thermo.temperature, 5)
        self.assertIsNot(type(self.thermo), Crashing)

    def start_new(self):
        self.provider_node = Node("sensor2", self.clock)
        self.thermo = Thermometer()
        self.provider = self.provider_node.provide(THERMO, self.thermo)

    def test_pending_call_fails_when_link_goes_down(self):
        class Stuck:
            def work(self, job):
                self.job = job

        itf = Interface("Stuck", 7, [Operation("work", 1, (), asynchronous=True)])
        self.provider_node.provide(itf, Stuck())
        pending = self.user.call("Stuck.work", (), timeout=1)
        self.assertTrue(pending.accepted)
        self.restart()
        with self.assertRaises(UnavailableError):
            pending.result(timeout=1)


if __name__ == "__main__":
    unittest.main()
