"""Queue and node from asyncio tasks, on CPython and on MicroPython (whose asyncio has no
Queue)."""

import asyncio
import unittest

from obsw.il.interface import DATA, Attribute, Event, Interface, Operation
from obsw.il.node import Node
from obsw.il.queue import BLOCK, EMPTY, Queue


def run(coro):
    return asyncio.run(coro)


class TestAsyncQueue(unittest.TestCase):
    def test_producer_consumer(self):
        q = Queue(2)
        got = []

        async def producer():
            for i in range(6):
                self.assertTrue(await q.asend(i, None))

        async def consumer():
            for _ in range(6):
                got.append(await q.areceive(None))

        async def main():
            await asyncio.gather(consumer(), producer())

        run(main())
        self.assertEqual(got, [0, 1, 2, 3, 4, 5])

    def test_receive_timeout_gives_empty(self):
        q = Queue(1)

        async def main():
            return await q.areceive(0.01), await q.areceive(0)

        self.assertEqual(run(main()), (EMPTY, EMPTY))

    def test_send_timeout_gives_false(self):
        q = Queue(1)
        q.send(1)

        async def main():
            return await q.asend(2, 0.01), await q.asend_to_front(2, 0)

        self.assertEqual(run(main()), (False, False))
        self.assertEqual(q.receive(), 1)

    def test_plain_send_wakes_waiting_task(self):
        q = Queue(1)

        async def waiter():
            return await q.areceive(5)

        async def main():
            t = asyncio.create_task(waiter())
            await asyncio.sleep(0)
            q.send("from plain code")
            return await t

        self.assertEqual(run(main()), "from plain code")

    def test_peek_and_front(self):
        q = Queue(3)

        async def main():
            await q.asend("b", 0)
            await q.asend_to_front("a", 0)
            first = await q.apeek(0)
            return first, [await q.areceive(0), await q.areceive(0)]

        self.assertEqual(run(main()), ("a", ["a", "b"]))

    def test_aput_block_policy(self):
        q = Queue(1, BLOCK, 5)
        q.put("x")

        async def drain():
            await asyncio.sleep(0)
            return q.receive()

        async def main():
            t = asyncio.create_task(drain())
            ok = await q.aput("y")
            return ok, await t

        self.assertEqual(run(main()), (True, "x"))
        self.assertEqual(q.receive(), "y")
        self.assertEqual(q.dropped, 0)

    def test_aput_block_policy_times_out(self):
        q = Queue(1, BLOCK, 0.01)
        q.put("x")
        self.assertFalse(run(q.aput("y")))
        self.assertEqual(q.dropped, 1)


COUNTER = Interface(
    "Counter",
    1,
    [
        Attribute("count", 1, DATA),
        Operation("add", 2, ("n",)),
        Operation("slow_add", 3, ("n",), asynchronous=True),
        Event("added", 4),
    ],
)


class Counter:
    count = 0

    def il_bind(self, provider):
        self.il = provider

    def add(self, n):
        self.il.update("count", self.count + n)
        self.il.emit("added", n)
        return self.count

    def slow_add(self, job, n):
        async def later():
            await asyncio.sleep(0)
            job.update("half")
            await asyncio.sleep(0)
            job.succeed(self.add(n))

        asyncio.create_task(later())


class TestAsyncNode(unittest.TestCase):
    def test_acall_and_aget_local(self):
        node = Node("n")
        node.provide(COUNTER, Counter())

        async def main():
            v = await node.acall("Counter.add", (5,), timeout=1)
            return v, await node.aget("Counter.count", timeout=1)

        self.assertEqual(run(main()), (5, 5))

    def test_async_operation_awaited(self):
        node = Node("n")
        node.provide(COUNTER, Counter())
        proxy = node.proxy(COUNTER, timeout=1)
        updates = []

        async def main():
            task = asyncio.create_task(node.serve())
            pending = proxy.slow_add(3, on_status=lambda p, s, v: updates.append(v))
            value = await pending.wait(5)
            task.cancel()
            return value

        self.assertEqual(run(main()), 3)
        self.assertEqual(updates, [None, "half", 3])

    def test_serve_runs_subscription_callbacks(self):
        node = Node("n")
        node.provide(COUNTER, Counter())
        seen = []
        node.subscribe("Counter.added", lambda pub: seen.append(pub.value), timeout=1)

        async def main():
            task = asyncio.create_task(node.serve())
            await asyncio.sleep(0)
            await node.acall("Counter.add", (2,), timeout=1)
            await node.acall("Counter.add", (4,), timeout=1)
            for _ in range(5):
                await asyncio.sleep(0)
            task.cancel()

        run(main())
        self.assertEqual(seen, [2, 4])

    def test_subscription_areceive(self):
        node = Node("n")
        node.provide(COUNTER, Counter())
        sub = node.subscribe("Counter.count", timeout=1)

        async def main():
            node.call("Counter.add", (9,), timeout=1)
            pub = await sub.areceive(1)
            return pub.member, pub.value

        self.assertEqual(run(main()), ("count", 9))


if __name__ == "__main__":
    unittest.main()
