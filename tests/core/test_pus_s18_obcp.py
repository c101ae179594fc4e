"""ST[18]: OBCPs uploaded, activated, reported, suspended, resumed, aborted and refused, the
provider (on the OBCP engine and the interaction layer) against the user, with the engine's
progress as service 5 events; one process, a simulated clock."""

import json
import unittest

from obsw.cfdp.filestore import MemoryFilestore
from obsw.il.errors import ComponentError
from obsw.il.interface import DATA, INFO, Attribute, Event, Interface, Operation
from obsw.il.node import Node
from obsw.pluto.engine import provide
from obsw.pluto.obcp import ENGINE
from obsw.pus.messages import (
    FAILURE_FILESTORE,
    FAILURE_ILLEGAL_SUBTYPE,
    FAILURE_OBCP_REJECTED,
    FAILURE_REFUSED,
    FAILURE_UNKNOWN_ID,
)
from obsw.pus.sdb import loads
from obsw.pus.services import s18_layouts as lay
from obsw.pus.services.s05_events import EventReporting, EventUser
from obsw.pus.services.s18_obcp import ObcpManagement
from obsw.pus.services.s18_user import ObcpUser, failure_info
from pus_loop import APID, Loop

T0 = 1735689600.0  # 2025-01-01T00:00:00Z
START = 2  # the stage of a start failure report

PANEL = Interface(
    "SolarPanel",
    0x50,
    [
        Attribute("angle", 1, DATA, type="f32", unit="deg"),
        Operation("set_angle", 2, ("angle",)),
        Event("angle_reached", 3, INFO),
    ],
)


class Panel:
    def __init__(self):
        self.angle = 0.0
        self.il = None

    def il_bind(self, provider):
        self.il = provider

    def set_angle(self, angle):
        if angle > 90:
            raise ComponentError("ANGLE_OUT_OF_RANGE", "too far")
        self.il.update("angle", float(angle))
        return angle


TURN = """procedure
  main
    initiate and confirm step Turn
      main
        log "from ", angle of SolarPanel;
        initiate and confirm set_angle of SolarPanel with arguments angle := 30 deg end with;
        log "to ", angle of SolarPanel;
      end main
    end step;
  end main
end procedure"""

HOLD = """procedure
  main
    initiate and confirm step Hold
      main
        wait for 10 s;
        log "held";
      end main
    end step;
    log "done";
  end main
end procedure"""

ASK = """procedure
  main
    initiate and confirm step Ask
      main
        if ask user ("go on?") expect Boolean then log "yes"; else log "no"; end if;
      end main
    end step;
  end main
end procedure"""


class Rig:
    def __init__(self, filestore=None, level=lay.LEVEL_STEP):
        self.loop = Loop()
        self.clock = self.loop.clock
        self.node = Node("obc", self.clock)
        self.panel = Panel()
        self.node.provide(PANEL, self.panel)
        self.engine = provide(self.node, timeout=0.5, activity_timeout=5.0, poll=0.5)
        self.sdb = loads(json.dumps({"events": lay.sdb_events(ENGINE)}))
        app = self.loop.app
        app.register(EventReporting())
        self.service = app.register(
            ObcpManagement(
                self.engine,
                filestore=filestore,
                events=self.sdb.event,
                level=level,
                clock=lambda: T0 + self.clock.now(),
            )
        )
        self.user = self.loop.ground.register(ObcpUser())
        self.events = self.loop.ground.register(EventUser(self.sdb.event))

    def run(self, tx):
        self.loop.pump()
        return tx

    def drive(self, seconds=2.0, step=0.25):
        end = self.clock.now() + seconds
        while self.clock.now() < end:
            self.node.poll()
            self.loop.app.tick()
            self.node.poll()
            self.loop.pump()
            self.clock.advance(step)

    def reported(self, name=None):
        """Decoded service 5 events (name, data), in order; only ``name`` if given."""
        out = []
        for tm, d, _tx in self.loop.results:
            if tm.service == 5 and d and "event" in d:
                ev = d["event"][len("obcp.") :]
                if name is None or ev == name:
                    out.append((ev, d["data"]))
        return out

    def status(self):
        tx = self.run(self.user.report_status(APID))
        return {o["id"]: o for o in tx.reply["obcps"]}


class TestUploadAndRun(unittest.TestCase):
    def test_upload_activate_and_events(self):
        r = Rig()
        tx = r.run(r.user.load(APID, "turn", TURN))
        self.assertTrue(tx.ok)
        self.assertEqual(tx.verification()[-1], "completion success")
        self.assertEqual(r.engine.obcps, ["turn"])
        tx = r.run(r.user.activate(APID, "turn", level=lay.LEVEL_STATEMENT))
        self.assertTrue(tx.ok)
        r.drive()
        self.assertEqual(r.panel.angle, 30.0)
        self.assertEqual(
            r.reported("step_status"),
            [
                ("step_status", {"obcp": "turn", "step": "Turn", "status": "executing"}),
                ("step_status", {"obcp": "turn", "step": "Turn", "status": "confirmed"}),
            ],
        )
        self.assertEqual(
            [d["text"] for _, d in r.reported("log")], ["from 0.0 deg", "to 30.0 deg"]
        )
        self.assertEqual(
            r.reported("finished"),
            [("finished", {"obcp": "turn", "outcome": "confirmed", "error": ""})],
        )
        self.assertEqual(r.reported("failed"), [])
        st = r.status()["turn"]
        self.assertEqual(
            (st["status"], st["outcome"], st["activations"], st["level"]),
            ("inactive", "confirmed", 1, "statement"),
        )
        self.assertTrue(st["statements"] > 0)

    def test_event_ids_and_severities_follow_the_database(self):
        r = Rig()
        r.run(r.user.load(APID, "turn", TURN))
        r.run(r.user.activate(APID, "turn"))
        r.drive()
        seen = {}
        for tm, d, _tx in r.loop.results:
            if tm.service == 5:
                seen[d["event"]] = (d["id"], tm.subtype)
        ev = r.sdb.event("obcp.step_status")
        self.assertEqual(seen["obcp.step_status"], (ev.id, ev.severity))
        self.assertEqual(seen["obcp.started"][0], lay.EVENT_BASE + 17)

    def test_arguments_declared_at_load_and_given_at_activation(self):
        r = Rig()
        src = "procedure main log target * 2; end main end procedure"
        tx = r.run(r.user.load(APID, "args", src, {"target": {"value": 1.5, "unit": "deg"}}))
        self.assertTrue(tx.ok)
        r.run(r.user.activate(APID, "args", {"target": {"value": 20.0, "unit": "deg"}}, 3))
        r.drive(1.0)
        r.run(r.user.activate(APID, "args", None, 3))
        r.drive(1.0)
        self.assertEqual([d["text"] for _, d in r.reported("log")], ["40.0 deg", "3.0 deg"])

    def test_status_while_running_suspend_resume_abort(self):
        r = Rig()
        r.run(r.user.load(APID, "hold", HOLD))
        r.run(r.user.activate(APID, "hold"))
        r.drive(1.0)
        st = r.status()["hold"]
        self.assertEqual((st["status"], st["step"], st["outcome"]), ("running", "Hold", "none"))
        self.assertEqual(st["line"], 5)
        self.assertTrue(r.run(r.user.suspend(APID, "hold")).ok)
        r.drive(10.0)  # at the next statement boundary: once the wait is over
        self.assertEqual(r.status()["hold"]["status"], "suspended")
        r.drive(20.0)  # a suspended OBCP does not go on, whatever the time
        self.assertEqual(r.status()["hold"]["status"], "suspended")
        self.assertTrue(r.run(r.user.resume(APID, "hold")).ok)
        r.drive(1.0)
        st = r.status()["hold"]
        self.assertEqual((st["status"], st["outcome"]), ("inactive", "confirmed"))
        r.run(r.user.activate(APID, "hold"))
        r.drive(1.0)
        self.assertTrue(r.run(r.user.abort(APID, "hold")).ok)
        st = r.status()["hold"]
        self.assertEqual(
            (st["status"], st["outcome"], st["activations"]), ("inactive", "aborted", 2)
        )
        states = [d["state"] for _, d in r.reported("state_changed")]
        self.assertEqual(
            states,
            ["inactive", "running", "suspended", "running", "inactive", "running", "inactive"],
        )
        self.assertEqual(r.reported("failed"), [])  # aborted on request is no failure

    def test_stop_ends_at_the_end_of_the_step(self):
        r = Rig()
        r.run(r.user.load(APID, "hold", HOLD))
        r.run(r.user.activate(APID, "hold", level=lay.LEVEL_STATEMENT))
        r.drive(1.0)
        self.assertTrue(r.run(r.user.stop(APID, "hold")).ok)
        self.assertEqual(r.status()["hold"]["status"], "stopping")
        r.drive(12.0)
        self.assertEqual(r.status()["hold"]["status"], "inactive")
        self.assertEqual([d["text"] for _, d in r.reported("log")][:1], ["held"])
        self.assertNotEqual([d["text"] for _, d in r.reported("log")][-1], "done")

    def test_communicate_parameters_answers_the_question(self):
        r = Rig(level=lay.LEVEL_STATEMENT)
        r.run(r.user.load(APID, "ask", ASK))
        r.run(r.user.activate(APID, "ask", level=lay.LEVEL_STATEMENT))
        r.drive(1.0)
        self.assertEqual(r.reported("question"), [("question", {"obcp": "ask", "text": "go on?"})])
        self.assertTrue(r.run(r.user.answer(APID, "ask", True)).ok)
        r.drive(1.0)
        self.assertEqual([d["text"] for _, d in r.reported("log")], ["yes"])
        tx = r.run(r.user.answer(APID, "ask", True))
        self.assertEqual(failure_info(tx.failure), {"reason": "NOT_ACTIVE", "obcp": "ask"})

    def test_load_by_reference_and_load_and_activate(self):
        fs = MemoryFilestore({"obcp/turn.plt": TURN.encode()})
        r = Rig(fs)
        self.assertTrue(r.run(r.user.load_by_reference(APID, "t1", "obcp", "turn.plt")).ok)
        tx = r.run(r.user.load_and_activate(APID, "t2", "obcp", "turn.plt"))
        self.assertTrue(tx.ok)
        self.assertEqual(r.engine.states, {"t1": "inactive", "t2": "running"})
        r.drive()
        self.assertEqual(r.panel.angle, 30.0)
        tx = r.run(r.user.load_by_reference(APID, "t3", "obcp", "nope.plt"))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (START, FAILURE_FILESTORE))
        self.assertEqual(failure_info(tx.failure), {"path": "obcp/nope.plt"})
        self.assertEqual(r.engine.obcps, ["t1", "t2"])

    def test_stop_and_unload_abort_all_and_the_engine(self):
        r = Rig()
        for name in ("a", "b", "c"):
            r.run(r.user.load(APID, name, HOLD))
        r.run(r.user.activate(APID, "a"))
        r.run(r.user.activate(APID, "b"))
        r.drive(1.0)
        tx = r.run(r.user.abort_all(APID))
        self.assertEqual(tx.reply, {"ids": ["a", "b"]})
        r.run(r.user.activate(APID, "c"))
        r.drive(1.0)
        self.assertTrue(r.run(r.user.stop_and_unload(APID, "c")).ok)
        self.assertEqual(r.engine.obcps, ["a", "b", "c"])  # until the step has ended
        r.drive(12.0)
        self.assertEqual(r.engine.obcps, ["a", "b"])
        self.assertTrue(r.run(r.user.stop_engine(APID)).ok)
        tx = r.run(r.user.activate(APID, "a"))
        self.assertEqual(failure_info(tx.failure), {"reason": "ENGINE_STOPPED", "obcp": "a"})
        self.assertTrue(r.run(r.user.start_engine(APID)).ok)
        self.assertTrue(r.run(r.user.activate(APID, "a")).ok)
        r.run(r.user.stop_engine(APID))  # aborts what runs
        self.assertEqual(r.engine.states, {"a": "inactive", "b": "inactive"})
        self.assertTrue(r.run(r.user.unload(APID, "a")).ok)
        self.assertEqual(list(r.status()), ["b"])


class TestRefusals(unittest.TestCase):
    def test_syntax_error_refused_with_line_and_column(self):
        r = Rig()
        tx = r.run(r.user.load(APID, "bad", "procedure\n  main\n    log 1\n  end main\nend"))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (START, FAILURE_OBCP_REJECTED))
        info = failure_info(tx.failure)
        self.assertEqual((info["kind"], info["line"], info["column"]), ("syntax_error", 4, 3))
        self.assertIn("expected", info["message"])
        self.assertEqual(r.engine.obcps, [])

    def test_unknown_reference_refused_with_line(self):
        r = Rig()
        src = "procedure main\n log tilt of SolarPanel;\nend main end procedure"
        tx = r.run(r.user.load(APID, "bad", src))
        info = failure_info(tx.failure)
        self.assertEqual((info["kind"], info["line"], info["column"]), ("unknown_reference", 2, 6))
        self.assertIn("tilt of SolarPanel", info["message"])

    def test_state_refusals_and_unknown_obcps(self):
        r = Rig()
        r.run(r.user.load(APID, "hold", HOLD))
        tx = r.run(r.user.load(APID, "hold", HOLD))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (START, FAILURE_REFUSED))
        self.assertEqual(failure_info(tx.failure), {"reason": "ALREADY_LOADED", "obcp": "hold"})
        tx = r.run(r.user.resume(APID, "hold"))
        self.assertEqual(failure_info(tx.failure)["reason"], "NOT_SUSPENDED")
        r.run(r.user.activate(APID, "hold"))
        tx = r.run(r.user.unload(APID, "hold"))
        self.assertEqual(failure_info(tx.failure)["reason"], "NOT_INACTIVE")
        tx = r.run(r.user.activate(APID, "nope"))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (START, FAILURE_UNKNOWN_ID))
        self.assertEqual(failure_info(tx.failure), {"obcp": "nope"})
        tx = r.run(r.user.set_observability(APID, {"nope": 1}))
        self.assertEqual(tx.failure["code"], FAILURE_UNKNOWN_ID)
        tx = r.run(r.loop.ground.send(APID, 18, 3, b"\x41" + b"x" * 65 + b"\x02\x00"))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (1, 5))  # too long an ID

    def test_failed_procedure_raises_failed_event(self):
        r = Rig()
        src = TURN.replace("30 deg", "120 deg")
        r.run(r.user.load(APID, "far", src))
        mark = len(r.reported())
        r.run(r.user.activate(APID, "far", level=lay.LEVEL_NONE))
        r.drive()
        got = r.reported()[mark:]
        self.assertEqual([n for n, _ in got], ["failed"])
        self.assertEqual(got[0][1], {"obcp": "far", "error": "not confirmed at line 6"})

    def test_observability_levels(self):
        r = Rig()
        r.run(r.user.load(APID, "turn", TURN))
        r.run(r.user.activate(APID, "turn", level=lay.LEVEL_PROCEDURE))
        r.drive()
        names = [n for n, _ in r.reported()]
        self.assertIn("finished", names)
        self.assertEqual(r.reported("step_status") + r.reported("log"), [])
        self.assertTrue(r.run(r.user.set_observability(APID, {"turn": 2})).ok)
        self.assertEqual(r.status()["turn"]["level"], "step")

    def test_step_by_step_refusals(self):
        r = Rig()
        r.run(r.user.load(APID, "steps", STEPS))
        tx = r.run(r.user.resume_and_step(APID, "steps"))
        self.assertEqual(failure_info(tx.failure), {"reason": "NOT_SUSPENDED", "obcp": "steps"})
        tx = r.run(r.user.activate_and_step(APID, "nope"))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (START, FAILURE_UNKNOWN_ID))
        self.assertTrue(r.run(r.user.activate_and_step(APID, "steps")).ok)
        tx = r.run(r.user.activate_and_step(APID, "steps"))
        self.assertEqual(failure_info(tx.failure), {"reason": "NOT_INACTIVE", "obcp": "steps"})
        tx = r.run(r.user.resume_and_step(APID, "steps"))  # running its first step
        self.assertEqual(failure_info(tx.failure)["reason"], "NOT_SUSPENDED")
        r.drive(8.0)
        self.assertEqual(r.status()["steps"]["status"], "suspended")
        r.run(r.user.stop_engine(APID))
        tx = r.run(r.user.resume_and_step(APID, "steps"))
        self.assertEqual(failure_info(tx.failure)["reason"], "ENGINE_STOPPED")
        tx = r.run(r.loop.ground.send(APID, 18, 15, b""))
        self.assertEqual(tx.failure["stage"], 1)  # no OBCP ID: not even accepted
        tx = r.run(r.loop.ground.send(APID, 18, 23, b"\x01a"))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (1, FAILURE_ILLEGAL_SUBTYPE))


STEPS = """procedure
  main
    log "before";
    initiate and confirm step One
      main
        log "one";
        wait for 5 s;
        log "one done";
      end main
    end step;
    log "between";
    initiate and confirm step Two
      main
        log "two";
      end main
    end step;
    log "after";
  end main
end procedure"""

NESTED = """procedure
  main
    initiate and confirm step Outer
      main
        initiate and confirm step Inner
          main
            log "inner";
          end main
        end step;
        log "outer";
      end main
    end step;
    log "end";
  end main
end procedure"""


class TestStepByStep(unittest.TestCase):
    def logs(self, r):
        return [d["text"] for _, d in r.reported("log")]

    def test_activate_and_execute_one_step_then_resume_one_step_at_a_time(self):
        r = Rig()
        self.assertTrue(r.run(r.user.load(APID, "steps", STEPS)).ok)
        tx = r.run(r.user.activate_and_step(APID, "steps", level=lay.LEVEL_STATEMENT))
        self.assertTrue(tx.ok, tx.verification())
        self.assertEqual(tx.verification()[-1], "completion success")
        r.drive(8.0)
        self.assertEqual(self.logs(r), ["before", "one", "one done"])
        st = r.status()["steps"]
        self.assertEqual((st["status"], st["outcome"], st["step"]), ("suspended", "none", ""))
        self.assertEqual(r.engine.status("steps")["steps"], {"One": "confirmed"})
        r.drive(20.0)  # held, whatever the time
        self.assertEqual(self.logs(r), ["before", "one", "one done"])
        self.assertTrue(r.run(r.user.resume_and_step(APID, "steps")).ok)
        r.drive(2.0)
        self.assertEqual(self.logs(r)[3:], ["between", "two"])
        self.assertEqual(r.status()["steps"]["status"], "suspended")
        self.assertTrue(r.run(r.user.resume_and_step(APID, "steps")).ok)
        r.drive(2.0)  # no step left: runs to its end
        self.assertEqual(self.logs(r)[5:], ["after"])
        st = r.status()["steps"]
        self.assertEqual((st["status"], st["outcome"]), ("inactive", "confirmed"))
        states = [d["state"] for _, d in r.reported("state_changed")]
        self.assertEqual(
            states,
            ["inactive", "running", "suspended", "running", "suspended", "running", "inactive"],
        )
        self.assertEqual(r.reported("failed"), [])

    def test_resume_leaves_step_by_step_mode(self):
        r = Rig(level=lay.LEVEL_STATEMENT)
        r.run(r.user.load(APID, "steps", STEPS))
        r.run(r.user.activate_and_step(APID, "steps", level=lay.LEVEL_STATEMENT))
        r.drive(8.0)
        self.assertEqual(r.status()["steps"]["status"], "suspended")
        self.assertTrue(r.run(r.user.resume(APID, "steps")).ok)
        r.drive(2.0)
        self.assertEqual(self.logs(r)[3:], ["between", "two", "after"])
        self.assertEqual(r.status()["steps"]["status"], "inactive")
        r.run(r.user.activate(APID, "steps", level=lay.LEVEL_STATEMENT))  # not step by step
        r.drive(8.0)
        self.assertEqual(len(self.logs(r)), 12)
        self.assertEqual(r.status()["steps"]["activations"], 2)

    def test_suspended_inside_a_step_resume_and_step_ends_that_step(self):
        r = Rig()
        r.run(r.user.load(APID, "hold", HOLD))
        r.run(r.user.activate(APID, "hold", level=lay.LEVEL_STATEMENT))
        r.drive(1.0)
        r.run(r.user.suspend(APID, "hold"))
        r.drive(10.0)  # at the boundary after the wait, inside step Hold
        st = r.status()["hold"]
        self.assertEqual((st["status"], st["step"]), ("suspended", "Hold"))
        self.assertTrue(r.run(r.user.resume_and_step(APID, "hold")).ok)
        r.drive(2.0)
        self.assertEqual(self.logs(r), ["held"])  # the rest of the step, not "done"
        st = r.status()["hold"]
        self.assertEqual((st["status"], st["step"]), ("suspended", ""))
        r.run(r.user.resume_and_step(APID, "hold"))
        r.drive(2.0)
        self.assertEqual(self.logs(r), ["held", "done"])
        self.assertEqual(r.status()["hold"]["outcome"], "confirmed")

    def test_a_step_is_an_outermost_step(self):
        r = Rig()
        r.run(r.user.load(APID, "nested", NESTED))
        r.run(r.user.activate_and_step(APID, "nested", level=lay.LEVEL_STATEMENT))
        r.drive(2.0)
        self.assertEqual(self.logs(r), ["inner", "outer"])
        self.assertEqual(r.status()["nested"]["status"], "suspended")
        r.run(r.user.resume_and_step(APID, "nested"))
        r.drive(2.0)
        self.assertEqual(self.logs(r), ["inner", "outer", "end"])

    def test_stop_and_abort_while_step_by_step(self):
        r = Rig()
        for name in ("a", "b"):
            r.run(r.user.load(APID, name, STEPS))
            r.run(r.user.activate_and_step(APID, name))
        r.drive(8.0)
        self.assertEqual(r.engine.states, {"a": "suspended", "b": "suspended"})
        self.assertTrue(r.run(r.user.stop(APID, "a")).ok)  # suspended between steps: at once
        self.assertTrue(r.run(r.user.abort(APID, "b")).ok)
        self.assertEqual(r.engine.states, {"a": "inactive", "b": "inactive"})
        self.assertEqual(r.engine.status("b")["outcome"], "aborted")


if __name__ == "__main__":
    unittest.main()
