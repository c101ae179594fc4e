"""The OBCP engine as an IL component: load, activate, several procedures at once, suspend,
resume, stop and abort through its operations, and the events it emits; one process, a
simulated clock."""

import unittest

from obsw.il.clock import SimClock
from obsw.il.errors import ComponentError
from obsw.il.interface import DATA, INFO, Attribute, Event, Interface, Operation
from obsw.il.node import Node
from obsw.pluto.engine import ObcpEngine, provide
from obsw.pluto.obcp import ENGINE, INACTIVE, RUNNING, STOPPING, SUSPENDED, ObcpError
from obsw.pluto.system import SimulatedSystem

try:
    import asyncio
except ImportError:  # a port without asyncio
    asyncio = None

T0 = 1735689600.0  # 2025-01-01T00:00:00Z

PANEL = Interface(
    "SolarPanel",
    0x50,
    [
        Attribute("angle", 1, DATA, type="f32", unit="deg"),
        Operation("set_angle", 2, ("angle",)),
        Operation("slew", 4, (), asynchronous=True),
        Event("angle_reached", 3, INFO),
    ],
)


class Panel:
    def __init__(self):
        self.angle = 0.0
        self.il = None
        self.jobs = []

    def slew(self, job):
        self.jobs.append(job)  # never finishes by itself

    def il_bind(self, provider):
        self.il = provider

    def set_angle(self, angle):
        if angle > 90:
            raise ComponentError("ANGLE_OUT_OF_RANGE", "too far")
        self.il.update("angle", float(angle))
        self.il.emit("angle_reached", {"angle": angle})
        return angle


def step(name, main, decl=""):
    return "initiate and confirm step %s %s main %s end main end step;" % (
        name,
        "declare %s end declare" % decl if decl else "",
        main,
    )


def proc(*body, decl=""):
    return "procedure %s main %s end main end procedure" % (
        "declare %s end declare" % decl if decl else "",
        " ".join(body),
    )


def one(main, decl=""):
    return proc(step("S", main, decl))


class Rig:
    def __init__(self, **options):
        self.clock = SimClock(T0)
        self.node = Node("obc", self.clock)
        self.panel = Panel()
        self.node.provide(PANEL, self.panel)
        options.setdefault("poll", 0.5)
        self.engine = provide(self.node, timeout=0.5, activity_timeout=5.0, **options)
        self.user = self.node.proxy(ENGINE, timeout=1.0)
        self.events = self.node.subscribe("ObcpEngine.*", timeout=1.0, length=256)
        self.seen = []

    def drive(self, limit_s=60, until=None):
        end = self.clock.now() + limit_s
        for _ in range(5000):
            self.node.poll()
            d = self.engine.step(self.clock.now())
            self.collect()
            if until is not None and until():
                return
            if d is None:
                return
            if d > self.clock.now():
                if d > end:
                    return
                self.clock.advance(d - self.clock.now())

    def collect(self):
        while True:
            pub = self.events.receive()
            if not pub:
                return self.seen
            if pub.member not in ("obcps", "states"):
                self.seen.append((pub.member, pub.value))

    def named(self, member):
        return [v for m, v in self.collect() if m == member]

    def texts(self, member="log"):
        return [(v["obcp"], v["text"]) for v in self.named(member)]


class TestLoading(unittest.TestCase):
    def test_load_list_and_unload(self):
        r = Rig()
        r.user.load("A", proc('log "a";'))
        r.user.load("B", proc('log "b";'))
        self.assertEqual(r.user.obcps, ["A", "B"])
        self.assertEqual(r.user.states, {"A": INACTIVE, "B": INACTIVE})
        self.assertEqual(r.user.status("A")["state"], INACTIVE)
        r.user.unload("A")
        self.assertEqual(r.user.obcps, ["B"])
        self.assertEqual(r.named("state_changed")[-1], {"obcp": "A", "state": "unloaded"})
        self.assertEqual([s["name"] for s in r.engine.list()], ["B"])

    def test_load_rejection_carries_line_and_kind(self):
        r = Rig()
        with self.assertRaises(ComponentError) as c:
            r.user.load("bad", "procedure main\n log tilt of SolarPanel;\nend main end procedure")
        e = c.exception
        self.assertEqual(e.code, "LOAD_FAILED")
        self.assertEqual((e.data["kind"], e.data["line"]), ("unknown_reference", 2))
        self.assertIn("tilt of SolarPanel", e.message)
        with self.assertRaises(ComponentError) as c:
            r.user.load("bad", "procedure main log 1 end procedure")
        self.assertEqual(c.exception.data["kind"], "syntax_error")
        self.assertEqual(r.user.obcps, [])

    def test_refusals(self):
        r = Rig(capacity=2)
        r.user.load("A", one("wait for 10 s;"))
        codes = []
        for call in (
            lambda: r.user.load("A", proc("log 1;")),
            lambda: r.user.load("", proc("log 1;")),
            lambda: r.user.activate("nope", None),
            lambda: r.user.suspend("A"),
            lambda: r.user.resume("A"),
            lambda: r.user.abort("A"),
            lambda: r.user.answer("A", "yes"),
        ):
            try:
                call()
            except ComponentError as e:
                codes.append(e.code)
        r.user.activate("A", None)
        for call in (
            lambda: r.user.activate("A", None),
            lambda: r.user.unload("A"),
            lambda: r.user.answer("A", 1),
        ):
            try:
                call()
            except ComponentError as e:
                codes.append(e.code)
        r.user.load("B", proc("log 1;"))
        with self.assertRaises(ObcpError) as c:
            r.engine.load("C", proc("log 1;"))
        codes.append(c.exception.code)
        self.assertEqual(codes, ["ALREADY_LOADED", "BAD_NAME", "UNKNOWN_OBCP", "NOT_RUNNING",
                                 "NOT_SUSPENDED", "NOT_ACTIVE", "NOT_ACTIVE", "NOT_INACTIVE",
                                 "NOT_INACTIVE", "NO_QUESTION", "NO_ROOM"])  # fmt: skip

    def test_load_file_and_bytes(self):
        r = Rig(check=False)
        r.engine.load_file("cpdu", "tests/data/pluto/cpdu_state_bits.pluto")
        r.engine.load("b", proc('log "bytes";').encode())
        self.assertEqual(r.engine.obcps, ["cpdu", "b"])
        with self.assertRaises(ObcpError) as c:
            r.engine.load_file("x", "tests/data/pluto/no_such_file.pluto")
        self.assertEqual(c.exception.code, "LOAD_FAILED")


class TestRunning(unittest.TestCase):
    def test_procedure_reads_calls_and_waits(self):
        r = Rig()
        r.user.load(
            "turn",
            proc(
                step(
                    "Turn",
                    'log "from ", angle of SolarPanel;'
                    " initiate and confirm set_angle of SolarPanel with arguments"
                    " angle := 30 deg end with;"
                    " wait until angle of SolarPanel > 29 deg timeout 5 s;"
                    ' inform user "at ", angle of SolarPanel;',
                )
            ),
        )
        r.user.activate("turn", None)
        r.drive()
        self.assertEqual(r.panel.angle, 30.0)
        self.assertEqual(r.texts(), [("turn", "from 0.0 deg")])
        self.assertEqual(r.texts("message"), [("turn", "at 30.0 deg")])
        self.assertEqual(
            r.named("step_status"),
            [
                {"obcp": "turn", "step": "Turn", "status": "executing"},
                {"obcp": "turn", "step": "Turn", "status": "confirmed"},
            ],
        )
        self.assertEqual(r.named("started"), [{"obcp": "turn"}])
        self.assertEqual(
            r.named("finished"), [{"obcp": "turn", "outcome": "confirmed", "error": None}]
        )
        st = r.user.status("turn")
        self.assertEqual((st["state"], st["outcome"], st["steps"]),
                         (INACTIVE, "confirmed", {"Turn": "confirmed"}))  # fmt: skip
        self.assertEqual(st["activations"], 1)

    def test_two_procedures_at_once(self):
        r = Rig()
        r.user.load("slow", one('wait for 10 s; log "slow";'))
        r.user.load("fast", one('wait for 4 s; log "fast"; wait for 2 s; log "fast again";'))
        r.user.activate("slow", None)
        r.user.activate("fast", None)
        self.assertEqual(r.user.states, {"slow": RUNNING, "fast": RUNNING})
        self.assertEqual(r.engine.active(), 2)
        r.drive()
        self.assertEqual(r.texts(), [("fast", "fast"), ("fast", "fast again"), ("slow", "slow")])
        self.assertEqual(r.clock.now() - T0, 10)
        self.assertEqual(r.user.states, {"slow": INACTIVE, "fast": INACTIVE})
        self.assertIsNone(r.engine.next_deadline())

    def test_reactivate_with_arguments(self):
        r = Rig()
        r.engine.load("p", proc("log n * 2;"), {"n": 1})
        r.user.activate("p", None)
        r.drive()
        r.user.activate("p", {"n": 21})
        r.drive()
        r.user.activate("p", {"n": {"value": 3, "unit": "V"}})
        r.drive()
        self.assertEqual([t for _, t in r.texts()], ["2", "42", "6 V"])
        self.assertEqual(r.user.status("p")["activations"], 3)

    def test_failure_emits_failed(self):
        r = Rig()
        r.user.load("p", proc("initiate and confirm set_angle of SolarPanel with arguments"
                              " angle := 120 deg end with; log 2;"))  # fmt: skip
        r.user.activate("p", None)
        r.drive()
        fin = r.named("finished")[0]
        self.assertEqual(fin["outcome"], "aborted")
        self.assertEqual(r.named("failed"), [{"obcp": "p", "error": fin["error"]}])
        logs = [t for _, t in r.texts()]
        self.assertIn("not confirmed: ComponentError ANGLE_OUT_OF_RANGE", logs[0])
        self.assertEqual(len(logs), 1)  # the abort is the status (finished, failed), no log

    def test_events_raised_and_questions(self):
        r = Rig()
        r.user.load(
            "ask",
            proc(
                step("Ask", 'if ask user ("go on?") expect Boolean then log "yes"; end if;'),
                "initiate and confirm set_angle of SolarPanel with arguments 10 deg end with"
                " in case confirmed: raise event Turned; end case;",
                decl="event Turned",
            ),
        )
        r.user.activate("ask", None)
        r.drive()
        self.assertEqual(r.texts("question"), [("ask", "go on?")])
        self.assertEqual(r.user.status("ask")["question"], "go on?")
        self.assertIsNone(r.engine.next_deadline())  # waits for the operator only
        r.user.answer("ask", "yes")
        r.drive()
        self.assertEqual(r.texts(), [("ask", "yes")])
        self.assertEqual(r.named("raised"), [{"obcp": "ask", "event": "Turned"}])
        self.assertEqual(r.user.status("ask")["outcome"], "confirmed")

    def test_waits_for_component_event(self):
        r = Rig()
        r.user.load("w", one("wait for event angle_reached of SolarPanel timeout 30 s;"
                             ' log "reached";'))  # fmt: skip
        r.user.activate("w", None)
        r.clock.call_later(7, lambda: r.panel.set_angle(3))
        r.drive()
        self.assertEqual(r.texts(), [("w", "reached")])
        self.assertEqual(r.clock.now() - T0, 7)

    def test_budget_keeps_step_bounded(self):
        r = Rig(budget=25)
        r.user.load("loop", one("x := 0; while TRUE do x := x + 1; end while;",
                                "variable x of type signed integer"))  # fmt: skip
        r.user.load("other", proc('log "other";'))
        r.user.activate("loop", None)
        r.user.activate("other", None)
        r.engine.step(T0)
        self.assertEqual(r.texts(), [("other", "other")])
        first = r.user.status("loop")["statements"]
        self.assertTrue(0 < first <= 26)
        self.assertEqual(r.engine.next_deadline(), T0)
        r.engine.step(T0)
        self.assertTrue(r.user.status("loop")["statements"] > first)
        r.user.abort("loop")
        self.assertEqual(r.user.states["loop"], INACTIVE)

    def test_plain_system_without_fork(self):
        sim = SimulatedSystem({"parameters": {"a of B": 3}})
        e = ObcpEngine(sim)
        seen = []
        e.on_event = lambda name, payload: seen.append(name)
        e.load("p", proc("log a of B;"))
        e.activate("p")
        self.assertIsNone(e.step(0))
        self.assertEqual(sim.logs, ["3"])
        self.assertEqual(seen, ["state_changed", "state_changed", "started", "finished",
                                "state_changed"])  # fmt: skip


class TestControl(unittest.TestCase):
    def test_suspend_and_resume(self):
        r = Rig()
        r.user.load("p", one('log "1"; wait for 5 s; log "2"; log "3";'))
        r.user.activate("p", None)
        r.engine.step(T0)
        r.user.suspend("p")
        self.assertEqual(r.user.status("p")["requested"], "suspend")
        r.clock.advance(5)
        r.drive()
        self.assertEqual(r.user.states["p"], SUSPENDED)
        self.assertEqual(r.texts(), [("p", "1")])
        r.clock.advance(100)
        r.drive()
        self.assertEqual(r.texts(), [("p", "1")])
        r.user.resume("p")
        r.drive()
        self.assertEqual([t for _, t in r.texts()], ["1", "2", "3"])
        states = [v["state"] for v in r.named("state_changed")]
        self.assertEqual(states, [INACTIVE, RUNNING, SUSPENDED, RUNNING, INACTIVE])

    def test_abort(self):
        r = Rig()
        r.user.load("p", proc(step("S", 'wait for 1 min; log "never";')))
        r.user.activate("p", None)
        r.drive(limit_s=10)
        r.user.abort("p")
        st = r.user.status("p")
        self.assertEqual((st["state"], st["outcome"], st["error"]),
                         (INACTIVE, "aborted", "aborted by request"))  # fmt: skip
        self.assertEqual(st["steps"], {"S": "aborted"})
        self.assertEqual(r.named("failed"), [])
        self.assertEqual(r.named("finished")[0]["outcome"], "aborted")
        self.assertIsNone(r.engine.next_deadline())

    def test_abort_suspended(self):
        r = Rig()
        r.user.load("p", proc("log 1; log 2;"))
        r.user.activate("p", None)
        r.user.suspend("p")
        r.drive()
        self.assertEqual(r.user.states["p"], SUSPENDED)
        r.user.abort("p")
        self.assertEqual(r.user.status("p")["outcome"], "aborted")

    def test_stop_at_end_of_step(self):
        r = Rig()
        r.user.load(
            "p",
            proc(
                step("A", 'log "a1"; wait for 10 s; log "a2";'),
                step("B", 'log "b";'),
            ),
        )
        r.user.activate("p", None)
        r.drive(limit_s=3)
        r.user.stop("p")
        self.assertEqual(r.user.states["p"], STOPPING)
        r.drive()
        st = r.user.status("p")
        why = "stopped by request at the end of step A"
        self.assertEqual([t for _, t in r.texts()], ["a1", "a2"])
        self.assertEqual(st["steps"], {"A": "confirmed"})
        self.assertEqual((st["state"], st["outcome"]), (INACTIVE, "aborted"))
        self.assertEqual(st["error"], why)
        self.assertEqual(r.named("failed"), [])

    def test_stop_outside_steps_is_immediate(self):
        r = Rig()
        r.user.load("p", proc("initiate and confirm slew of SolarPanel; log 2;"))
        r.user.activate("p", None)
        r.drive(limit_s=2)
        self.assertEqual(len(r.panel.jobs), 1)
        r.user.stop("p")
        self.assertEqual(r.user.status("p")["error"], "stopped by request")
        r.drive()
        self.assertEqual(r.texts(), [])  # the abort is in the status only

    def test_step_by_step_through_the_proxy(self):
        r = Rig()
        r.user.load(
            "p",
            proc(
                'log "pre";',
                step("A", 'log "a1"; wait for 10 s; log "a2";'),
                step("B", 'log "b";'),
                'log "post";',
            ),
        )
        r.user.activate_step("p", None)
        r.drive()
        self.assertEqual(r.user.states["p"], SUSPENDED)
        self.assertEqual([t for _, t in r.texts()], ["pre", "a1", "a2"])
        self.assertTrue(r.user.status("p")["stepping"])
        self.assertIsNone(r.engine.next_deadline())  # held: nothing due
        r.user.resume_step("p")
        r.drive()
        self.assertEqual([t for _, t in r.texts()][3:], ["b"])
        self.assertEqual(r.user.states["p"], SUSPENDED)
        r.user.resume_step("p")
        r.drive()
        st = r.user.status("p")
        self.assertEqual((st["state"], st["outcome"]), (INACTIVE, "confirmed"))
        self.assertEqual([t for _, t in r.texts()][4:], ["post"])
        with self.assertRaises(ComponentError) as ctx:
            r.user.resume_step("p")
        self.assertEqual(ctx.exception.code, "NOT_SUSPENDED")

    def test_step_by_step_without_steps_runs_to_the_end(self):
        r = Rig()
        r.user.load("p", proc('log "1"; log "2";'))
        r.user.activate_step("p", None)
        r.drive()
        st = r.user.status("p")
        self.assertEqual((st["state"], st["outcome"]), (INACTIVE, "confirmed"))
        self.assertEqual([t for _, t in r.texts()], ["1", "2"])

    def test_resume_cancels_pending_suspend(self):
        r = Rig()
        r.user.load("p", one('wait for 3 s; log "x";'))
        r.user.activate("p", None)
        r.engine.step(T0)
        r.user.suspend("p")
        r.user.resume("p")
        r.drive()
        self.assertEqual(r.texts(), [("p", "x")])

    @unittest.skipIf(asyncio is None, "no asyncio")
    def test_serve_from_asyncio_task(self):
        r = Rig()
        r.user.load("p", proc('log "served";'))
        done = []

        async def main():
            task = asyncio.create_task(r.engine.serve(r.clock.now, idle=0.05))
            r.user.activate("p", None)
            for _ in range(200):
                if r.user.states["p"] == INACTIVE:
                    break
                await asyncio.sleep(0)
            done.append(r.user.status("p")["outcome"])
            task.cancel()
            try:
                await task
            except asyncio.CancelledError:
                pass

        asyncio.run(main())
        self.assertEqual(done, ["confirmed"])
        self.assertEqual(r.texts(), [("p", "served")])
        self.assertIsNone(r.engine.on_wake)


if __name__ == "__main__":
    unittest.main()
