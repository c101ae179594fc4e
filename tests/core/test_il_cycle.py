"""Cycle detection: a synchronous call that would close a cycle fails at once, naming it, in
one node and across nodes; asynchronous calls break the cycle."""

import unittest

from obsw.il.clock import SimClock
from obsw.il.errors import CycleError, InteractionError
from obsw.il.interface import Interface, Operation
from obsw.il.loopback import resolver_for
from obsw.il.node import Node


def interface(name, ident):
    return Interface(
        name,
        ident,
        [
            Operation("ping", 1, ("target",)),
            Operation("kick", 2, ("target",)),
            Operation("echo", 3, ("value",)),
            Operation("later", 4, ("target",), asynchronous=True),
        ],
    )


A, B, C = interface("A", 1), interface("B", 2), interface("C", 3)


class Component:
    """``ping(target)`` calls ``target.ping`` (or ``echo`` at the end of a path) synchronously."""

    def __init__(self, name):
        self.name = name
        self.node = None
        self.log = []

    def il_bind(self, provider):
        self.il = provider
        self.node = provider.node

    def ping(self, path):
        self.log.append(path)
        if not path:
            return self.name
        nxt, rest = path[0], path[1:]
        return self.name + ">" + self.node.call(nxt + ".ping", (rest,), timeout=1.0)

    def kick(self, target):
        """Asynchronous invocation: nothing waits, so no cycle can close."""
        self.node.start(target + ".echo", (self.name,), timeout=1.0)
        return "kicked"

    def echo(self, value):
        self.log.append(value)
        return value

    def later(self, job, target):
        job.succeed(target)


class TestOneNode(unittest.TestCase):
    def setUp(self):
        self.node = Node("obc", SimClock())
        self.parts = {}
        for itf in (A, B, C):
            name = itf.name
            self.parts[name] = Component(name)
            self.node.provide(itf, self.parts[name])

    def test_chain_without_cycle(self):
        self.assertEqual(self.node.call("A.ping", (["B", "C"],), timeout=1), "A>B>C")

    def test_two_component_cycle(self):
        with self.assertRaises(CycleError) as cm:
            self.node.call("A.ping", (["B", "A"],), timeout=1)
        e = cm.exception
        self.assertEqual(e.cycle, ("A", "B", "A"))
        self.assertIn("A -> B -> A", str(e))
        self.assertIsInstance(e, InteractionError)

    def test_three_component_cycle(self):
        with self.assertRaises(CycleError) as cm:
            self.node.call("A.ping", (["B", "C", "A"],), timeout=1)
        self.assertEqual(cm.exception.cycle, ("A", "B", "C", "A"))

    def test_self_call(self):
        with self.assertRaises(CycleError) as cm:
            self.node.call("A.ping", (["A"],), timeout=1)
        self.assertEqual(cm.exception.cycle, ("A", "A"))

    def test_fails_at_once_without_waiting(self):
        clock = self.node.clock
        with self.assertRaises(CycleError):
            self.node.call("A.ping", (["B", "A"],), timeout=100)
        self.assertEqual(clock.now(), 0)

    def test_user_identity_counts(self):
        with self.assertRaises(CycleError) as cm:
            self.node.call("B.ping", (["A"],), timeout=1, user="A")
        self.assertEqual(cm.exception.cycle, ("A", "B", "A"))
        proxy = self.node.proxy(B, timeout=1, user="C")
        with self.assertRaises(CycleError):
            proxy.ping(["C"])

    def test_asynchronous_invocation_breaks_the_cycle(self):
        self.assertEqual(self.node.call("A.kick", ("A",), timeout=1), "kicked")
        self.node.poll()
        self.assertEqual(self.parts["A"].log, ["A"])

    def test_busy_state_is_cleared_after_a_cycle(self):
        with self.assertRaises(CycleError):
            self.node.call("A.ping", (["B", "A"],), timeout=1)
        self.assertEqual(self.node._busy, [])
        self.assertEqual(self.node.call("A.ping", (["B"],), timeout=1), "A>B")


class TestAcrossNodes(unittest.TestCase):
    """A, B and C each in their own node, joined by CBOR loopback links."""

    def setUp(self):
        self.clock = SimClock()
        self.nodes = []
        for itf in (A, B, C):
            name = itf.name
            node = Node("proc-" + name, self.clock)
            node.provide(itf, Component(name))
            self.nodes.append(node)
        self.user = Node("user", self.clock)
        everyone = lambda: self.nodes + [self.user]  # noqa: E731
        for node in everyone():
            node.registry.resolver = resolver_for(node, everyone, codec=True)

    def test_remote_chain(self):
        self.assertEqual(self.user.call("A.ping", (["B", "C"],), timeout=1), "A>B>C")

    def test_remote_cycle_named(self):
        with self.assertRaises(CycleError) as cm:
            self.user.call("A.ping", (["B", "A"],), timeout=1)
        self.assertEqual(cm.exception.cycle, ("A", "B", "A"))
        self.assertEqual(self.clock.now(), 0)

    def test_remote_three_cycle(self):
        with self.assertRaises(CycleError) as cm:
            self.user.call("A.ping", (["B", "C", "A"],), timeout=1)
        self.assertEqual(cm.exception.cycle, ("A", "B", "C", "A"))

    def test_incoming_request_for_a_waiting_component(self):
        # A waits on B; a request for A arrives whose chain shows it comes from B's work
        node_a = self.nodes[0]
        provider = node_a.registry.resolve("A")
        provider.busy = True
        node_a._waits["A"] = "B"
        replies = []

        class Origin:
            def deliver(self, msg):
                replies.append(msg)

        node_a.deliver([1, 5, "A", "echo", ["x"], ["D", "B"]], Origin())
        self.assertEqual(replies[0][2], CycleError.status)
        self.assertEqual(replies[0][3][2], ["A", "B", "A"])
        self.assertEqual(provider.inbox.messages_waiting(), 0)


if __name__ == "__main__":
    unittest.main()
