"""The PUS application process: routing, verification, faults, tasks, cyclic activity."""

try:
    import asyncio
except ImportError:  # the unix port keeps asyncio frozen under ".frozen", off a custom path
    import sys

    sys.path.append(".frozen")
    import asyncio
import unittest

from obsw.compat import MICROPYTHON
from obsw.pus.app import EVENT_CYCLE_OVERRUN
from obsw.pus.packets import (
    ACK_ACCEPTANCE,
    ACK_ALL,
    ACK_COMPLETION,
    ACK_NONE,
    ACK_PROGRESS,
    RequestId,
)
from obsw.pus.services.base import Service
from obsw.pus.services.s01_verification import (
    FAILURE_BUSY,
    FAILURE_EXECUTION,
    FAILURE_TIMEOUT,
    PusFailure,
)
from obsw.pus.services.s05_events import EventReporting
from obsw.pus.services.s17_test import ServiceTest, ServiceTestUser
from obsw.pus.tc import PusTc
from obsw.pus.tm import PusTm
from pus_loop import APID, Loop

_SLOW = (200, 1)
_BOOM = (200, 2)
_STEPS = (200, 3)
_FAIL_STEP = (200, 4)
_WAIT = (200, 5)


class Custom(Service):
    SERVICE = 200
    HANDLERS = (
        (_SLOW, "slow"),
        (_BOOM, "boom"),
        (_STEPS, "steps"),
        (_FAIL_STEP, "fail_step"),
        (_WAIT, "wait"),
    )

    def __init__(self):
        super().__init__()
        self.order = []
        self.gate = None

    async def slow(self, req):
        self.order.append(("begin", req.tc.seq_count))
        req.start()
        await asyncio.sleep(0)
        await asyncio.sleep(0)
        self.order.append(("end", req.tc.seq_count))

    def boom(self, req):
        req.start()
        raise RuntimeError("defect")

    def steps(self, req):
        req.progress(1)
        req.progress(2)

    def fail_step(self, req):
        req.progress(1)
        raise PusFailure(42, data=b"\x01", step=2)

    async def wait(self, req):
        self.gate = asyncio.Event()
        await self.gate.wait()


class Cyclic(Service):
    SERVICE = 201

    def __init__(self, clock=None, spend=0):
        super().__init__()
        self.clock = clock
        self.spend = spend
        self.calls = 0

    def cyclic(self, now):
        self.calls += 1
        if self.spend:
            self.clock.advance(self.spend)


class Hanging(Service):
    SERVICE = 202

    def __init__(self):
        super().__init__()
        self.started = 0

    async def cyclic(self, now):
        self.started += 1
        await asyncio.Event().wait()


def make():
    loop = Loop()
    loop.app.register(ServiceTest())
    user = loop.ground.register(ServiceTestUser())
    return loop, user


def tc(service, subtype, data=b"", seq=0, apid=APID, ack=ACK_ALL):
    return PusTc(apid, service, subtype, data, seq, ack, source_id=7).pack()


class TestRouting(unittest.TestCase):
    def test_ping_reports_in_order(self):
        loop, user = make()
        tx = loop.run(user.ping(APID))
        self.assertEqual(loop.types(), [(1, 1), (1, 3), (17, 2), (1, 7)])
        self.assertTrue(tx.ok)
        self.assertEqual(tx.reply, {"alive": True})
        self.assertEqual(
            tx.verification(), ["acceptance success", "start success", "completion success"]
        )
        self.assertEqual(loop.tm[0].destination_id, 7)

    def test_ack_flags_choose_success_reports(self):
        for ack, expected in (
            (ACK_NONE, [(17, 2)]),
            (ACK_ACCEPTANCE, [(1, 1), (17, 2)]),
            (ACK_COMPLETION, [(17, 2), (1, 7)]),
            (ACK_ALL, [(1, 1), (1, 3), (17, 2), (1, 7)]),
        ):
            loop, user = make()
            loop.app.receive(tc(17, 1, ack=ack))
            loop.pump()
            self.assertEqual(loop.types(), expected)

    def test_sequence_and_message_type_counters(self):
        loop, user = make()
        for _ in range(3):
            loop.run(user.ping(APID))
        self.assertEqual([t.seq_count for t in loop.tm], list(range(12)))
        self.assertEqual([t.message_counter for t in loop.tm if t.subtype == 2], [0, 1, 2])
        self.assertEqual(
            [t.message_counter for t in loop.tm if (t.service, t.subtype) == (1, 7)], [0, 1, 2]
        )
        self.assertEqual(loop.app.tc_counts[(17 << 8) | 1], 3)
        self.assertEqual(loop.app.counters["completed"], 3)

    def test_the_reports_of_a_tc_carry_one_time(self):
        calls = []

        def now():  # on-board time that moves on at each look
            calls.append(1)
            return 1000.0 + len(calls)

        loop = Loop(time=now)
        loop.app.register(ServiceTest())
        user = loop.ground.register(ServiceTestUser())
        loop.run(user.ping(APID))
        loop.run(user.ping(APID))
        times = [t.time for t in loop.tm]
        self.assertEqual(len(set(times[:4])), 1)  # the first TC's four reports
        self.assertEqual(len(set(times[4:])), 1)  # the second's
        self.assertNotEqual(times[0], times[4])
        self.assertEqual(len(calls), 2)

    def test_a_tm_too_long_leaves_no_gap_in_the_counts(self):
        loop, user = make()
        heard = []
        loop.app.unsent_listeners.append(lambda *a: heard.append(a))
        loop.run(user.ping(APID))
        self.assertIsNone(loop.app.send_tm(17, 2, bytes(70000), 7))  # over the packet size
        self.assertEqual(loop.app.counters["tm_unpackable"], 1)
        self.assertEqual([(s, t) for s, t, _ in heard], [(17, 2)])
        loop.run(user.ping(APID))
        self.assertEqual([t.seq_count for t in loop.tm], list(range(8)))
        self.assertEqual([t.message_counter for t in loop.tm if t.subtype == 2], [0, 1])

    def test_progress_reports(self):
        loop = Loop()
        loop.app.register(Custom())
        loop.app.receive(tc(200, 3, ack=ACK_ALL | ACK_PROGRESS))
        loop.app.receive(tc(200, 3, seq=1, ack=ACK_ALL & ~ACK_PROGRESS))
        loop.pump()
        self.assertEqual(
            loop.types(),
            [(1, 1), (1, 3), (1, 5), (1, 5), (1, 7), (1, 1), (1, 3), (1, 7)],
        )
        self.assertEqual(loop.tm[3].data[4], 2)  # step ID

    def test_progress_failure(self):
        loop = Loop()
        loop.app.register(Custom())
        loop.app.receive(tc(200, 4, ack=ACK_ALL | ACK_PROGRESS))
        loop.pump()
        self.assertEqual(loop.types(), [(1, 1), (1, 3), (1, 5), (1, 6)])
        self.assertEqual(loop.tm[3].data[4:], b"\x02\x2a\x01")  # step, code, data


class TestBadInput(unittest.TestCase):
    def failure(self, raw):
        loop, user = make()
        loop.app.receive(raw)
        loop.pump()
        return loop

    def check(self, raw, subtype, code):
        loop = self.failure(raw)
        self.assertEqual(loop.types(), [(1, subtype)])
        report = loop.tm[0]
        self.assertEqual(report.data[4], code)
        self.assertEqual(loop.app.failures[code], 1)
        # the process keeps serving
        loop.app.receive(tc(17, 1, seq=9))
        loop.pump()
        self.assertEqual(loop.types()[-1], (1, 7))
        return loop

    def test_wrong_crc(self):
        raw = bytearray(tc(17, 1, seq=5))
        raw[-1] ^= 0xFF
        loop = self.check(bytes(raw), 2, 2)
        self.assertEqual(RequestId.unpack(loop.tm[0].data), RequestId(APID, 5))

    def test_wrong_length(self):
        self.check(tc(17, 1) + b"\x00", 2, 1)
        raw = bytearray(tc(17, 1))
        raw[5] += 4  # the length field claims more than came
        self.check(bytes(raw), 2, 1)

    def test_unknown_service_and_subtype(self):
        self.check(tc(99, 1), 2, 3)
        self.check(tc(17, 99), 2, 4)

    def test_bad_application_data(self):
        self.check(tc(17, 1, b"\x00"), 2, 5)
        self.check(tc(17, 3, b"\x00"), 2, 5)

    def test_wrong_apid(self):
        self.check(tc(17, 1, apid=APID + 1), 2, 0)

    def test_tm_given_as_tc(self):
        self.check(PusTm(APID, 17, 2).pack(), 2, 6)

    def test_unreadable_header_is_a_counted_drop(self):
        for raw in (b"", b"\x18", b"\x18\x0a\xc0"):
            loop = self.failure(raw)
            self.assertEqual(loop.tm, [])
        self.assertEqual(loop.app.counters["dropped"], 1)

    def test_handler_defect_fails_the_request(self):
        loop = Loop()
        loop.app.register(Custom())
        loop.app.receive(tc(200, 2))
        loop.pump()
        self.assertEqual(loop.types(), [(1, 1), (1, 3), (1, 8)])
        self.assertEqual(loop.tm[-1].data[4], FAILURE_EXECUTION)
        self.assertEqual(loop.app.counters["handler_errors"], 1)

    def test_output_failure_is_counted(self):
        loop = Loop()

        def broken(raw):
            raise OSError("link down")

        loop.app.out = broken
        loop.app.register(ServiceTest())
        loop.app.receive(tc(17, 1))
        self.assertEqual(loop.app.counters["tm_lost"], 4)
        self.assertEqual(loop.app.counters["completed"], 1)


class TestTasks(unittest.TestCase):
    def test_async_handlers_run_concurrently(self):
        loop = Loop()
        custom = loop.app.register(Custom())

        def send():
            loop.app.receive(tc(200, 1, seq=1))
            loop.app.receive(tc(200, 1, seq=2))
            return None

        loop.run_async(send)
        self.assertEqual(custom.order, [("begin", 1), ("begin", 2), ("end", 1), ("end", 2)])
        self.assertEqual(loop.types().count((1, 7)), 2)
        self.assertEqual(loop.app.tasks, [])

    def test_too_many_tasks_is_busy(self):
        loop = Loop(max_tasks=1)
        loop.app.register(Custom())

        def send():
            loop.app.receive(tc(200, 1, seq=1))
            loop.app.receive(tc(200, 1, seq=2))

        loop.run_async(send)
        self.assertEqual(loop.app.failures[FAILURE_BUSY], 1)
        self.assertIn((1, 2), loop.types())
        self.assertEqual(loop.types().count((1, 7)), 1)

    def test_stuck_handler_times_out(self):
        loop = Loop(task_timeout=5.0)
        loop.app.register(Custom())

        async def main():
            loop.app.receive(tc(200, 5))
            await asyncio.sleep(0)
            self.assertEqual(len(loop.app.tasks), 1)
            loop.clock.advance(6)
            loop.app.tick()
            await loop.app.idle()

        asyncio.run(main())
        loop.pump()
        self.assertEqual(loop.types(), [(1, 2)])
        self.assertEqual(loop.tm[0].data[4], FAILURE_TIMEOUT)

    @unittest.skipIf(MICROPYTHON, "MicroPython queues the task for a loop started later")
    def test_async_handler_without_loop_fails(self):
        loop = Loop()
        loop.app.register(Custom())
        loop.app.receive(tc(200, 1))
        loop.pump()
        self.assertEqual(loop.types(), [(1, 2)])
        self.assertEqual(loop.tm[0].data[4], FAILURE_EXECUTION)


class TestCyclic(unittest.TestCase):
    def test_tick_runs_cyclic_work(self):
        loop = Loop()
        c = loop.app.register(Cyclic())
        for _ in range(3):
            loop.app.tick()
        self.assertEqual(c.calls, 3)
        self.assertEqual(loop.app.counters.get("overruns", 0), 0)

    def test_overrun_of_plain_cyclic_work_is_an_event(self):
        loop = Loop(period=0.1)
        loop.app.register(EventReporting())
        loop.app.register(Cyclic(loop.clock, spend=0.5))
        self.assertEqual(loop.app.tick(), 1)
        loop.pump()
        self.assertEqual(loop.types(), [(5, 3)])
        self.assertEqual(loop.tm[0].data, b"\xff\x01\x00")

    def test_hanging_cyclic_task_is_stopped_and_reported(self):
        loop = Loop()
        loop.app.register(EventReporting())
        h = loop.app.register(Hanging())

        async def main():
            overruns = 0
            for _ in range(3):
                overruns += loop.app.tick()
                await asyncio.sleep(0)
                await asyncio.sleep(0)
            return overruns

        overruns = asyncio.run(main())
        loop.pump()
        self.assertEqual(overruns, 2)
        self.assertEqual(h.started, 3)
        self.assertEqual(loop.types(), [(5, 3), (5, 3)])
        self.assertEqual(loop.tm[0].data, bytes((EVENT_CYCLE_OVERRUN >> 8, 0x01, 202)))

    def test_run_loop_counts_cycles(self):
        loop = Loop()
        c = loop.app.register(Cyclic())
        asyncio.run(loop.app.run(0.001, cycles=4))
        self.assertEqual(c.calls, 4)


if __name__ == "__main__":
    unittest.main()
