"""Interaction layer in one process: interfaces, proxies, direct calls, errors, timeouts,
retries and the registry finding a restarted provider."""

import unittest

from obsw.il.clock import SimClock
from obsw.il.errors import (
    ArgumentError,
    BusyError,
    CallTimeoutError,
    ComponentError,
    InteractionError,
    ProviderError,
    ReadOnlyError,
    UnavailableError,
    UnknownMemberError,
)
from obsw.il.interface import (
    CONFIGURATION,
    DATA,
    HIGH,
    Attribute,
    Event,
    Interface,
    Operation,
    check_unique_ids,
)
from obsw.il.message import split_name
from obsw.il.node import Node
from obsw.il.queue import DROP_NEWEST, OVERWRITE_OLDEST

PANEL = Interface(
    "SolarPanel",
    0x10,
    [
        Attribute("angle", 1, DATA, type="f32", unit="deg"),
        Attribute("speed", 2, CONFIGURATION, type="f32", unit="deg/s"),
        Operation("set_angle", 3, ("angle",)),
        Operation("stow", 4),
        Operation("move", 5, ("angle",), asynchronous=True),
        Event("angle_reached", 6),
        Event("jammed", 7, HIGH),
    ],
)


class Panel:
    """A solar panel that moves at ``speed`` degrees per simulated second."""

    def __init__(self, clock):
        self.clock = clock
        self.angle = 0.0
        self._speed = 10.0
        self.il = None

    def il_bind(self, provider):
        self.il = provider

    @property
    def speed(self):
        return self._speed

    @speed.setter
    def speed(self, value):
        if not 0 < value <= 45:
            raise ValueError("speed out of range", value)
        self._speed = value

    def set_angle(self, angle):
        if not -90 <= angle <= 90:
            raise ComponentError("ANGLE_OUT_OF_RANGE", "angle beyond the hinge", {"angle": angle})
        self.il.update("angle", angle)
        self.il.emit("angle_reached", {"angle": angle})
        return angle

    def stow(self):
        return self.set_angle(0)

    def move(self, job, angle):
        if not -90 <= angle <= 90:
            job.fail(ComponentError("ANGLE_OUT_OF_RANGE", "angle beyond the hinge", angle))
            return
        steps = int(abs(angle - self.angle) // self._speed) or 1
        start = self.angle

        def step(i):
            def run():
                a = start + (angle - start) * i / steps
                if i < steps:
                    job.update(a)
                else:
                    self.set_angle(angle)
                    job.succeed(angle)

            return run

        for i in range(1, steps + 1):
            self.clock.call_later(float(i), step(i))


class Setup(unittest.TestCase):
    def setUp(self):
        self.clock = SimClock()
        self.node = Node("obc", self.clock)
        self.panel = Panel(self.clock)
        self.provider = self.node.provide(PANEL, self.panel)
        self.proxy = self.node.proxy(PANEL, timeout=1.0)


class TestInterface(unittest.TestCase):
    def test_members_by_name_and_id(self):
        self.assertIs(PANEL.member("set_angle"), PANEL.member(3))
        self.assertEqual([a.name for a in PANEL.attributes], ["angle", "speed"])
        self.assertEqual(len(PANEL.operations), 3)
        self.assertEqual([e.severity for e in PANEL.events], [1, HIGH])
        self.assertTrue(PANEL.member("speed").writable)
        self.assertFalse(PANEL.member("angle").writable)
        self.assertIsNone(PANEL.member("nope"))
        self.assertIn("SolarPanel", repr(PANEL))

    def test_ids_and_names_unique(self):
        with self.assertRaises(ValueError):
            Interface("X", 1, [Attribute("a", 1), Event("b", 1)])
        with self.assertRaises(ValueError):
            Interface("X", 1, [Attribute("a", 1), Event("a", 2)])
        with self.assertRaises(ValueError):
            check_unique_ids([PANEL, Interface("Other", 0x10, [])])
        with self.assertRaises(ValueError):
            check_unique_ids([PANEL, Interface("SolarPanel", 0x11, [])])
        check_unique_ids([PANEL, Interface("Other", 0x11, [])])

    def test_bad_declarations(self):
        with self.assertRaises(ValueError):
            Attribute("a.b", 1)
        with self.assertRaises(ValueError):
            Attribute("a", -1)
        with self.assertRaises(ValueError):
            Attribute("a", 1, kind=5)
        with self.assertRaises(ValueError):
            Event("e", 1, severity=9)

    def test_split_name(self):
        self.assertEqual(split_name("SolarPanel.set_angle"), ("SolarPanel", "set_angle"))
        for bad in ("SolarPanel", ".x", "x.", 5):
            with self.assertRaises(ValueError):
                split_name(bad)


class TestCalls(Setup):
    def test_proxy_operation_and_attributes(self):
        self.assertEqual(self.proxy.set_angle(30), 30)
        self.assertEqual(self.proxy.get("angle"), 30)
        self.assertEqual(self.proxy.angle, 30)
        self.assertEqual(self.proxy.stow(), 0)
        self.assertEqual(self.proxy.set_angle(angle=12), 12)

    def test_direct_path_by_name(self):
        self.assertEqual(self.node.call("SolarPanel.set_angle", [45], timeout=1), 45)
        self.assertEqual(self.node.get("SolarPanel.angle", timeout=1), 45)
        self.node.set("SolarPanel.speed", 5.0, timeout=1)
        self.assertEqual(self.node.get("SolarPanel.speed", timeout=1), 5.0)

    def test_nothing_is_serialized_in_process(self):
        payload = {"big": bytearray(1000)}
        seen = []

        class Sink:
            def take(self, value):
                seen.append(value)
                return value

        itf = Interface("Sink", 1, [Operation("take", 1, ("value",))])
        self.node.provide(itf, Sink())
        self.assertIs(self.node.call("Sink.take", (payload,), timeout=1), payload)
        self.assertIs(seen[0], payload)

    def test_configuration_attribute_set(self):
        self.proxy.set("speed", 20.0)
        self.assertEqual(self.panel.speed, 20.0)

    def test_set_validation_error_reaches_caller(self):
        with self.assertRaises(ProviderError) as cm:
            self.proxy.set("speed", 100.0)
        e = cm.exception
        self.assertEqual(e.type, "ValueError")
        self.assertEqual(e.data, ["speed out of range", 100.0])
        self.assertEqual(e.target, "SolarPanel.speed")
        self.assertEqual(self.panel.speed, 10.0)

    def test_data_attribute_is_read_only(self):
        with self.assertRaises(ReadOnlyError):
            self.proxy.set("angle", 3)

    def test_component_error_keeps_code_and_data(self):
        with self.assertRaises(ComponentError) as cm:
            self.proxy.set_angle(120)
        self.assertEqual(cm.exception.code, "ANGLE_OUT_OF_RANGE")
        self.assertEqual(cm.exception.data, {"angle": 120})
        self.assertEqual(cm.exception.target, "SolarPanel.set_angle")
        self.assertIsInstance(cm.exception, InteractionError)
        self.assertIsInstance(cm.exception, RuntimeError)

    def test_unknown_member_and_bad_arguments(self):
        with self.assertRaises(UnknownMemberError):
            self.node.call("SolarPanel.fold", (), timeout=1)
        with self.assertRaises(UnknownMemberError):
            self.node.get("SolarPanel.set_angle", timeout=1)
        with self.assertRaises(ArgumentError) as cm:
            self.node.call("SolarPanel.set_angle", (1, 2), timeout=1)
        self.assertIn("takes 1 argument", str(cm.exception))
        with self.assertRaises(TypeError):
            self.proxy.set_angle(colour=3)
        with self.assertRaises(AttributeError):
            _ = self.proxy.colour

    def test_provider_keeps_serving_after_errors(self):
        for _ in range(3):
            with self.assertRaises(ComponentError):
                self.proxy.set_angle(99)
        self.assertEqual(self.proxy.set_angle(1), 1)
        self.assertEqual(self.provider.handled, 4)

    def test_timeout_must_be_valid(self):
        with self.assertRaises(ValueError):
            self.node.get("SolarPanel.angle", timeout=-1)
        with self.assertRaises(ValueError):
            self.node.proxy(PANEL, timeout=-1)


class TestAsynchronousOperation(Setup):
    def test_status_updates_then_result(self):
        updates = []
        pending = self.proxy.move(30, on_status=lambda p, state, v: updates.append((state, v)))
        self.assertFalse(pending.done)
        self.assertEqual(pending.result(timeout=10), 30)
        self.assertEqual(self.clock.now(), 3.0)
        self.assertEqual(updates, [(1, None), (1, 10.0), (1, 20.0), (2, 30)])
        self.assertEqual(self.panel.angle, 30)

    def test_result_times_out(self):
        pending = self.proxy.move(90)
        with self.assertRaises(CallTimeoutError):
            pending.result(timeout=2.5)
        self.assertTrue(pending.accepted)
        self.assertEqual(pending.progress, 20.0)
        self.assertEqual(pending.result(timeout=10), 90)

    def test_failed_operation_raises_typed_error(self):
        pending = self.proxy.move(200)
        with self.assertRaises(ComponentError) as cm:
            pending.result(timeout=100)
        self.assertEqual(cm.exception.code, "ANGLE_OUT_OF_RANGE")

    def test_synchronous_call_of_async_operation_returns_pending(self):
        pending = self.node.call("SolarPanel.move", (10,), timeout=1)
        self.assertTrue(pending.accepted)
        self.assertEqual(pending.result(timeout=5), 10)

    def test_job_fail(self):
        class Failing:
            def work(self, job):
                self.job = job

        impl = Failing()
        itf = Interface("W", 2, [Operation("work", 1, (), asynchronous=True)])
        self.node.provide(itf, impl)
        pending = self.node.start("W.work", timeout=1)
        self.node.poll()
        impl.job.fail("motor stalled")
        with self.assertRaises(ProviderError) as cm:
            pending.result(timeout=0)
        self.assertEqual(cm.exception.type, "RuntimeError")
        self.assertIn("motor stalled", str(cm.exception))


class TestRegistryAndRetries(Setup):
    def test_unavailable_after_timeout(self):
        with self.assertRaises(UnavailableError) as cm:
            self.node.get("Magnetometer.field", timeout=0.2)
        self.assertIn("Magnetometer", str(cm.exception))
        self.assertAlmostEqual(self.clock.now(), 0.2)

    def test_restarted_provider_found_again(self):
        self.assertEqual(self.proxy.set_angle(10), 10)
        self.node.withdraw(self.provider)
        with self.assertRaises(UnavailableError):
            self.proxy.get("angle")
        restarted = Panel(self.clock)
        self.node.provide(PANEL, restarted)
        self.assertEqual(self.proxy.get("angle"), 0.0)
        self.proxy.set_angle(5)
        self.assertEqual(restarted.angle, 5)

    def test_call_waits_for_provider_to_come_back(self):
        self.node.withdraw(self.provider)
        self.clock.call_at(0.3, lambda: self.node.provide(PANEL, Panel(self.clock)))
        self.assertEqual(self.proxy.set_angle(7), 7)
        self.assertTrue(0.3 <= self.clock.now() < 0.4)

    def test_bounded_retries(self):
        self.node.withdraw(self.provider)
        proxy = self.node.proxy(PANEL, timeout=0.5, retries=2)
        with self.assertRaises(UnavailableError):
            proxy.get("angle")
        self.assertEqual(self.node.retries, 2)
        self.assertAlmostEqual(self.clock.now(), 1.5)

    def test_retry_succeeds_when_provider_returns(self):
        self.node.withdraw(self.provider)
        proxy = self.node.proxy(PANEL, timeout=0.5, retries=3)
        self.clock.call_at(1.2, lambda: self.node.provide(PANEL, Panel(self.clock)))
        self.assertEqual(proxy.get("angle"), 0.0)
        self.assertEqual(self.node.retries, 2)

    def test_local_timeout_when_provider_is_slow(self):
        clock = self.clock

        class Slow:
            def work(self):
                clock.advance(2.0)
                return "late"

        itf = Interface("Slow", 3, [Operation("work", 1)])
        self.node.provide(itf, Slow())
        first = self.node.start("Slow.work", timeout=1)
        with self.assertRaises(CallTimeoutError):
            self.node.call("Slow.work", (), timeout=1.0)
        self.assertEqual(first.result(timeout=0), "late")


class TestInboxPolicies(Setup):
    def make(self, policy):
        class Sink:
            def __init__(self):
                self.got = []

            def take(self, v):
                self.got.append(v)
                return v

        sink = Sink()
        itf = Interface("Sink", 9, [Operation("take", 1, ("v",))])
        provider = self.node.provide(itf, sink, inbox=2, policy=policy)
        return sink, provider

    def test_drop_newest_refuses_with_busy(self):
        sink, provider = self.make(DROP_NEWEST)
        pend = [self.node.start("Sink.take", (i,), timeout=1) for i in range(3)]
        self.assertTrue(pend[2].done)
        with self.assertRaises(BusyError):
            pend[2].result(timeout=0)
        self.node.poll()
        self.assertEqual(sink.got, [0, 1])
        self.assertEqual(provider.inbox.dropped, 1)

    def test_overwrite_oldest_refuses_the_oldest(self):
        sink, provider = self.make(OVERWRITE_OLDEST)
        pend = [self.node.start("Sink.take", (i,), timeout=1) for i in range(3)]
        with self.assertRaises(BusyError):
            pend[0].result(timeout=0)
        self.node.poll()
        self.assertEqual(sink.got, [1, 2])
        self.assertEqual(pend[2].result(timeout=0), 2)

    def test_block_makes_room_by_running_the_provider(self):
        sink, provider = self.make(0)
        pend = [self.node.start("Sink.take", (i,), timeout=1) for i in range(4)]
        self.assertEqual(sink.got, [0, 1])
        self.node.poll()
        self.assertEqual([p.result(timeout=0) for p in pend], [0, 1, 2, 3])
        self.assertEqual(provider.inbox.dropped, 0)


if __name__ == "__main__":
    unittest.main()
