"""PLUTO interpreter: each statement, continuation actions, timeouts, parallel, watchdog and
control between statements, against the simulated system on a virtual clock."""

import unittest

from obsw.pluto.interp import Procedure, load
from obsw.pluto.system import SimulatedSystem, run_virtual
from obsw.pluto.units import AbsTime, Quantity

START = "2025-01-01T00:00:00Z"


def run(src, spec=None, args=None):
    spec = dict(spec or {})
    spec.setdefault("clock_start", START)
    sim = SimulatedSystem(spec)
    p = Procedure(load(src, sim if len(spec) > 1 else None, args), sim, args)
    p.start(sim.now)
    end = run_virtual(p, sim)
    return p, sim, end - sim.start


def step(main, decl="", extra="", cont=""):
    return (
        "procedure %s\ninitiate and confirm step S\n%s\nmain\n%s\nend main\nend step %s;\n"
        "end procedure" % (extra, "declare %s end declare" % decl if decl else "", main, cont)
    )


V = "variable x of type signed integer, variable r of type real, variable s of type string"


class TestStatements(unittest.TestCase):
    def test_assignment_and_arithmetic(self):
        p, sim, _ = run(step("x := 2 + 3 * 4 - trunc(10 / 5); log x; r := 2 ** 10 / 4; log r;", V))
        self.assertEqual(sim.logs, ["12", "256.0"])
        self.assertEqual(p.outcome, "confirmed")

    def test_if_else(self):
        p, sim, _ = run(
            step("x := 3; if x > 2 AND NOT (x = 5) then log 1; else log 2; end if;", V)
        )
        self.assertEqual(sim.logs, ["1"])

    def test_case(self):
        src = (
            "x := %d; in case x is = 1: log 1; or is between 2 and 4 OR > 100: log 2;"
            " or is in (7, 8): log 3; otherwise: log 4; end case;"
        )
        logs = [run(step(src % n, V))[1].logs[0] for n in (1, 3, 200, 8, 50)]
        self.assertEqual(logs, ["1", "2", "2", "3", "4"])

    def test_while_repeat_for(self):
        p, sim, _ = run(
            step(
                "x := 0; while x < 3 do x := x + 1; end while; log x;"
                " repeat x := x - 2; until x < 0; log x;"
                " for x := 10 to 4 by -3 do log x; end for;",
                V,
            )
        )
        self.assertEqual(sim.logs, ["3", "-1", "10", "7", "4"])

    def test_for_with_units(self):
        p, sim, _ = run(
            step(
                "for v := 1 V to 1.5 V by 250 mV do log v; end for;",
                "variable v of type real with units V",
            )  # fmt: skip
        )
        self.assertEqual(sim.logs, ["1.0 V", "1.25 V", "1.5 V"])

    def test_wait_for_relative_time(self):
        p, sim, end = run(step("wait for 1 min 30 s; log 1;"))
        self.assertEqual(end, 90)

    def test_wait_until_absolute_time(self):
        p, sim, end = run(step("wait until 2025-01-01T01:00:00Z;"))
        self.assertEqual(end, 3600)

    def test_wait_until_condition(self):
        spec = {"parameters": {"voltage of EPS": {"timeline": [[0, 6], [42, 8]], "unit": "V"}}}
        p, sim, end = run(step("wait until voltage of EPS > 7.5 V; log voltage of EPS;"), spec)
        self.assertEqual((end, sim.logs), (42, ["8 V"]))

    def test_wait_for_system_event(self):
        spec = {"events": [{"name": "Ready of Camera", "at_s": [12]}]}
        p, sim, end = run(step("wait for event Ready of Camera;"), spec)
        self.assertEqual(end, 12)

    def test_log_and_inform_user(self):
        p, sim, _ = run(step('log "a", 1, TRUE; inform user "t=", 2025-01-01T00:00:00Z;'))
        self.assertEqual(sim.logs, ["a1TRUE"])
        self.assertEqual(sim.user_messages, ["t=2025-01-01T00:00:00.000Z"])

    def test_parameter_references(self):
        spec = {"parameters": {"angle of SolarPanel": {"value": 30, "unit": "deg"},
                               "mode of OBC": "SAFE"}}  # fmt: skip
        p, sim, _ = run(
            step('log value of angle of SolarPanel; log mode of OBC = "SAFE";'
                 " log sin(angle of SolarPanel) within 1 % of 0.5;"), spec)  # fmt: skip
        self.assertEqual(sim.logs, ["30 deg", "TRUE", "TRUE"])
        self.assertEqual(sim.parameter_reads, ["angle of SolarPanel", "mode of OBC"])

    def test_context(self):
        spec = {"parameters": {"angle of SolarPanel": 4}}
        p, sim, _ = run(step("in the context of SolarPanel do log angle; end context;"), spec)
        self.assertEqual(sim.logs, ["4"])

    def test_variable_units_conversion(self):
        sim = SimulatedSystem({})
        p = Procedure(
            load(step("v := 3.3 V + 100 mV;", "variable v of type real with units mV")), sim
        )
        p.start(0)
        p.run(0)
        v = list(p.vars.values())[0]
        self.assertEqual(v.unit, "mV")
        self.assertAlmostEqual(v.value, 3400)
        p, sim, _ = run(step("v := 5; log v;", "variable v of type real with units mV"))
        self.assertEqual(sim.logs, ["5.0 mV"])

    def test_builtins(self):
        p, sim, _ = run(
            step(
                'log sqrt(16), abs(-2), max(1, 5, 3), min(2 V, 900 mV), length("abc"),'
                ' substring("abcdef", 2, 3), round(2.5), trunc(-2.5), 0x10;'
                " log current time() - 2025-01-01T00:00:00Z;"
            )
        )
        self.assertEqual(sim.logs, ["4.025900 mV3bcd3-216", "0 s"])

    def test_between_within_in(self):
        p, sim, _ = run(step("log 5 between 1 and 5, 10.2 V within 300 mV of 10 V, 3 in (1, 2);"))
        self.assertEqual(sim.logs, ["TRUETRUEFALSE"])

    def test_initiate_and_refer_by(self):
        spec = {"activities": {"heat of Heater": {"confirmation": "confirmed", "duration_s": 5}}}
        p, sim, end = run(
            step("initiate heat of Heater with arguments level := 2 end with refer by H;"
                 " log H; wait for 6 s; log H;"), spec)  # fmt: skip
        self.assertEqual(sim.logs, ["executing", "confirmed"])
        self.assertEqual(sim.activity_calls[0]["mode"], "initiate")
        self.assertEqual(sim.activity_calls[0]["arguments"], {"level": 2})

    def test_initiate_and_confirm_arguments(self):
        spec = {"activities": {"set_state_bits of CpduN": {"duration_s": 2}}}
        p, sim, end = run(
            step("initiate and confirm set_state_bits of CpduN with arguments state := 0x05,"
                 " gain := 2 V, record a := 1 end record, array 1, 2 end array end with;"),
            spec,
        )  # fmt: skip
        c = sim.activity_calls[0]
        self.assertEqual(c["mode"], "initiate and confirm")
        self.assertEqual(c["arguments"], {"state": 5, "gain": {"value": 2, "unit": "V"},
                                          "arg3": {"a": 1}, "arg4": [1, 2]})  # fmt: skip
        self.assertEqual((end, p.outcome), (2, "confirmed"))

    def test_operation_request(self):
        p, sim, _ = run(step("switch on of Heater with level := 3 end with;"))
        self.assertEqual(sim.activity_calls[0]["activity"], "switch on of Heater")

    def test_ask_user_expression(self):
        spec = {"user_responses": ["yes"], "parameters": {"a of B": 1}}
        p, sim, _ = run(
            step('if ask user ("proceed?") expect Boolean then log "go"; end if;'), spec
        )
        self.assertEqual((sim.user_prompts, sim.logs), (["proceed?"], ["go"]))

    def test_ask_user_waits_for_answer(self):
        sim = SimulatedSystem({})
        p = Procedure(load(step('r := ask user ("gain?") expect real; log r;', V)), sim)
        p.start(0)
        w = p.run(0)
        self.assertEqual((w.prompt, p.question), ("gain?", "gain?"))
        self.assertIsNone(p.run(5).deadline)
        p.answer("2.5")
        p.run(6)
        self.assertEqual((sim.logs, p.outcome), (["2.5"], "confirmed"))

    def test_runtime_error_aborts(self):
        p, sim, _ = run(step("x := 0; log 1 / x; log 2;", V))
        self.assertEqual(p.outcome, "aborted")
        self.assertIn("division by zero", p.error)
        self.assertIn("line 5", p.error)
        self.assertEqual(sim.logs, [])  # the abort is the status, not a log line

    def test_step_variables_fresh_on_restart(self):
        spec = {"parameters": {"a of B": 1}}
        p, sim, _ = run(
            step("log 1;", "", "", "in case confirmed: restart max times 1 raise event E;"
                 " end case")
            .replace("procedure", "procedure declare event E end declare", 1), spec)  # fmt: skip
        self.assertEqual(sim.logs, ["1", "1"])
        self.assertEqual(sim.events_raised[0]["event"], "E")

    def test_procedure_arguments(self):
        p, sim, _ = run(step("log level * 2;"), None, {"level": 21})
        self.assertEqual(sim.logs, ["42"])


class TestDecisions(unittest.TestCase):
    def test_false_precondition_aborts(self):
        p, sim, _ = run("procedure preconditions if 1 > 2 end preconditions log 1; end procedure")
        self.assertEqual((p.outcome, sim.logs[:0]), ("aborted", []))
        self.assertEqual(len([x for x in sim.logs if x == "1"]), 0)

    def test_step_precondition_false_is_step_aborted(self):
        src = step("log 1;").replace(
            "main\nlog", "preconditions if FALSE end preconditions main\nlog"
        )
        p, sim, _ = run(src.replace("end step", "end step in case aborted: continue; end case"))
        self.assertEqual((p.step_status["S"], p.outcome), ("aborted", "confirmed"))

    def test_timeout_raises_event_and_ends_step_main(self):
        src = step(
            "wait until FALSE timeout 10 s raise event Late; log 1;", "event Late",
            "", "in case not confirmed: continue; end case",
        ).replace("end step", 'confirmation if TRUE end confirmation end step')  # fmt: skip
        p, sim, end = run(src)
        self.assertEqual(sim.events_raised, [{"event": "Late", "at_s": 10}])
        self.assertEqual(sim.logs, [])
        self.assertEqual((p.step_status["S"], end), ("confirmed", 10))

    def test_timeout_without_confirmation_is_not_confirmed(self):
        src = step(
            "wait for 1 min timeout 5 s; log 1;",
            "",
            "",
            "in case not confirmed: continue; end case",
        )
        p, sim, end = run(src)
        self.assertEqual((p.step_status["S"], p.outcome, end), ("not confirmed", "confirmed", 5))

    def test_loop_timeout(self):
        src = step(
            "x := 0; while TRUE timeout 3 s raise event E do x := x + 1; wait for 1 s; end while;",
            V + ", event E", "", "in case not confirmed: continue; end case",
        )  # fmt: skip
        p, sim, end = run(src)
        self.assertEqual((end, sim.events_raised[0]["event"]), (3, "E"))
        self.assertEqual(p.step_status["S"], "not confirmed")

    def test_repeat_and_for_timeouts(self):
        for body in (
            "repeat wait for 2 s; until FALSE timeout 5 s;",
            "for x := 1 to 100 timeout 5 s do wait for 2 s; end for;",
        ):
            p, sim, end = run(step(body, V, "", "in case not confirmed: continue; end case"))
            self.assertEqual(end, 5)

    def test_raise_event_continues(self):
        spec = {"activities": {"a of B": {"confirmation": "not confirmed"}}}
        src = step("initiate and confirm a of B in case not confirmed: raise event E; end case;"
                   " log 2;", "event E")  # fmt: skip
        p, sim, _ = run(src, spec)
        self.assertEqual(
            (sim.events_raised[0]["event"], sim.logs, p.outcome), ("E", ["2"], "confirmed")
        )

    def test_default_not_confirmed_aborts(self):
        spec = {"activities": {"a of B": {"confirmation": "not confirmed"}}}
        p, sim, _ = run(step("initiate and confirm a of B; log 2;"), spec)
        self.assertEqual(p.outcome, "aborted")
        self.assertEqual(p.step_status["S"], "aborted")

    def test_resume_and_continue(self):
        for act in ("resume", "continue"):
            spec = {"activities": {"a of B": {"confirmation": "aborted"}}}
            src = step("initiate and confirm a of B in case aborted: %s; end case; log 2;" % act)
            p, sim, _ = run(src, spec)
            self.assertEqual((sim.logs, p.outcome), (["2"], "confirmed"))

    def test_restart_max_times(self):
        spec = {"activities": {"a of B": {"confirmations": ["not confirmed"] * 2 + ["confirmed"]}}}
        src = step(
            "initiate and confirm a of B in case not confirmed: restart max times 3; end case;"
        )
        p, sim, _ = run(src, spec)
        self.assertEqual((len(sim.activity_calls), p.outcome), (3, "confirmed"))

    def test_restart_exhausted(self):
        spec = {"activities": {"a of B": {"confirmation": "not confirmed"}}}
        src = step("initiate and confirm a of B in case not confirmed: restart max times 2"
                   " raise event E; end case; log 2;", "event E")  # fmt: skip
        p, sim, _ = run(src, spec)
        self.assertEqual((len(sim.activity_calls), sim.logs), (3, ["2"]))
        self.assertEqual(sim.events_raised[0]["event"], "E")
        src = step(
            "initiate and confirm a of B in case not confirmed: restart max times 1; end case;"
        )
        p, sim, _ = run(src, spec)
        self.assertEqual((len(sim.activity_calls), p.outcome), (2, "aborted"))

    def test_restart_with_timeout(self):
        spec = {"activities": {"a of B": {"confirmation": "not confirmed", "duration_s": 4}}}
        src = step("initiate and confirm a of B in case not confirmed: restart timeout 10 s"
                   " raise event E; end case;", "event E")  # fmt: skip
        p, sim, end = run(src, spec)
        self.assertEqual((len(sim.activity_calls), end), (3, 12))

    def test_ask_user_continuation(self):
        spec = {"activities": {"a of B": {"confirmation": "not confirmed"}},
                "user_responses": ["continue"]}  # fmt: skip
        src = step("initiate and confirm a of B in case not confirmed: ask user; end case; log 2;")
        p, sim, _ = run(src, spec)
        self.assertEqual((sim.logs, p.outcome), (["2"], "confirmed"))
        self.assertIn("a of B not confirmed", sim.user_prompts[0])

    def test_terminate_runs_confirmation(self):
        spec = {
            "activities": {"a of B": {"confirmation": "not confirmed"}},
            "parameters": {"t of U": 1},
        }
        src = (
            "procedure initiate and confirm step S main initiate and confirm a of B in case"
            " not confirmed: terminate; end case; log 2; end main confirmation if t of U = 1"
            " end confirmation end step; log 3; end procedure"
        )
        p, sim, _ = run(src, spec)
        self.assertEqual(
            (sim.logs, p.step_status["S"], p.outcome), (["3"], "confirmed", "confirmed")
        )
        self.assertEqual(sim.parameter_reads, ["t of U"])

    def test_procedure_confirmation_body(self):
        spec = {"parameters": {"t of U": 5}}
        p, sim, _ = run(
            "procedure log 1; confirmation if t of U < 3 end confirmation end procedure", spec
        )
        self.assertEqual(p.outcome, "not confirmed")

    def test_watchdog_abort_aborts_procedure(self):
        spec = {"events": [{"name": "Overheat of Thermal", "at_s": [5]}]}
        src = (
            "procedure main initiate and confirm step S main wait for 1 min; log 1; end main"
            " end step;"
            " end main watchdog initiate and confirm step Guard preconditions wait for event"
            ' Overheat of Thermal end preconditions main log "cool"; end main end step in case'
            " confirmed: abort; end case; end watchdog end procedure"
        )
        p, sim, end = run(src, spec)
        self.assertEqual((sim.logs[0], p.outcome, end), ("cool", "aborted", 5))

    def test_watchdog_resume(self):
        spec = {"parameters": {"temp of T": {"timeline": [[0, 20], [3, 80], [4, 20]]}}}
        src = (
            "procedure main initiate and confirm step S main wait for 10 s; log 1; end main"
            " end step;"
            " end main watchdog initiate and confirm step Guard preconditions if temp of T > 50"
            ' end preconditions main log "hot"; end main end step; end watchdog end procedure'
        )
        p, sim, end = run(src, spec)
        self.assertEqual((sim.logs, p.outcome, end), (["hot", "1"], "confirmed", 10))
        self.assertEqual(p.step_status["Guard"], "confirmed")


class TestParallelAndControl(unittest.TestCase):
    SPEC = {"activities": {"A": {"duration_s": 3}, "B": {"duration_s": 5}}}

    def test_parallel_until_all(self):
        p, sim, end = run("procedure in parallel until all complete initiate and confirm A;"
                          " initiate and confirm B; end parallel; log 1; end procedure",
                          self.SPEC)  # fmt: skip
        self.assertEqual((end, [c["at_s"] for c in sim.activity_calls]), (5, [0, 0]))

    def test_parallel_until_one(self):
        src = (
            "procedure in parallel until one completes initiate and confirm B;"
            " initiate and confirm step S main wait for 2 s; log 1; end main end step;"
            " end parallel; end procedure"
        )
        p, sim, end = run(src, self.SPEC)
        self.assertEqual((end, sim.logs, p.outcome), (2, ["1"], "confirmed"))

    def test_parallel_until_one_aborts_the_rest(self):
        src = (
            "procedure in parallel until one completes initiate and confirm A;"
            " initiate and confirm step S main wait for 9 s; log 1; end main end step;"
            " end parallel; end procedure"
        )
        p, sim, end = run(src, self.SPEC)
        self.assertEqual((end, sim.logs, p.step_status["S"]), (3, [], "aborted"))

    def test_step_executes_one_statement(self):
        sim = SimulatedSystem({})
        p = Procedure(load(step("log 1; log 2; log 3;")), sim)
        p.start(0)
        p.step(0)
        p.step(0)
        self.assertEqual(sim.logs, ["1"])
        p.step(0)
        self.assertEqual(sim.logs, ["1", "2"])
        p.run(0)
        self.assertEqual((sim.logs, p.state), (["1", "2", "3"], "finished"))

    def test_suspend_resume(self):
        sim = SimulatedSystem({})
        p = Procedure(load(step("log 1; wait for 5 s; log 2; log 3;")), sim)
        p.start(0)
        w = p.run(0)
        self.assertEqual(w.deadline, 5)
        p.suspend()
        self.assertIsNone(p.run(5))
        self.assertEqual((p.state, sim.logs), ("suspended", ["1"]))
        self.assertIsNone(p.run(6))
        p.resume()
        p.run(7)
        self.assertEqual((p.state, sim.logs), ("finished", ["1", "2", "3"]))

    def test_abort_between_statements(self):
        sim = SimulatedSystem({"activities": {"A": {"duration_s": 50}}})
        p = Procedure(load(step("initiate and confirm A; log 2;")), sim)
        p.start(0)
        w = p.run(0)
        self.assertEqual(w.activities, [0])
        p.abort("operator")
        self.assertEqual((p.state, p.outcome, p.error), ("finished", "aborted", "operator"))
        self.assertEqual(sim.status(0), "aborted")
        self.assertIsNone(p.run(100))
        self.assertEqual(sim.logs, [])

    def test_wait_reports_deadline_and_activity(self):
        sim = SimulatedSystem({"activities": {"A": {"duration_s": 50}}})
        p = Procedure(load(step("initiate and confirm A;")), sim, poll=2)
        p.start(100)
        w = p.run(100)
        self.assertEqual((w.deadline, w.activities), (102, [0]))

    def test_thesis_cpdu_example(self):
        with open("tests/data/pluto/cpdu_state_bits.pluto") as f:
            src = f.read()
        spec = {
            "parameters": {"state of CpduN": {"timeline": [[0, 0], [1, 5]]}},
            "activities": {
                "set_state_bits of CpduN": {"confirmation": "confirmed", "duration_s": 1}
            },
        }
        p, sim, end = run(src, spec)
        self.assertEqual(p.outcome, "confirmed")
        self.assertEqual(sim.activity_calls[0]["activity"], "set_state_bits of CpduN")
        self.assertEqual(sim.activity_calls[0]["arguments"], {"state": 5})


class TestValues(unittest.TestCase):
    def test_current_time_is_the_clock(self):
        sim = SimulatedSystem({})
        p = Procedure(load(step("t := current time();", "variable t of type absolute time")), sim)
        p.start(1000)
        p.run(1000)
        self.assertEqual(list(p.vars.values()), [AbsTime(1000)])

    def test_relative_time_variable(self):
        sim = SimulatedSystem({})
        p = Procedure(load(step("d := 2 min;", "variable d of type relative time")), sim)
        p.start(0)
        p.run(0)
        self.assertEqual(list(p.vars.values()), [Quantity(120, "s")])


class TestConformance(unittest.TestCase):
    SPEC = {
        "parameters": {
            "voltage of Bat": {"value": 3.3, "unit": "V"},
            "temp of Bat": {"timeline": [[0, 10], [5, 30.5]], "unit": "degC"},
        }
    }

    def test_parameter_compared_in_its_unit(self):
        p, sim, _ = run(step(
            "if voltage of Bat = 3300 mV then log 1; end if;"
            " if voltage of Bat > 3299 mV AND voltage of Bat < 3301 mV then log 2; end if;"
            " if 3300 mV = voltage of Bat then log 3; end if;"
            " if voltage of Bat > 3.4 V then log 4; end if;"
        ), self.SPEC)  # fmt: skip
        self.assertEqual(p.outcome, "confirmed")
        self.assertEqual(sim.logs, ["1", "2", "3"])

    def test_timeline_value_compared_in_its_unit(self):
        p, sim, end = run(step(
            "if temp of Bat = 283.15 K then log 1; end if;"
            " wait until temp of Bat > 303 K timeout 20 s; log 2;"
        ), self.SPEC)  # fmt: skip
        self.assertEqual(p.outcome, "confirmed")
        self.assertEqual(sim.logs, ["1", "2"])
        self.assertEqual(end, 5)

    def test_log_holds_only_what_log_statements_wrote(self):
        p, sim, _ = run(step("log 1; x := 0; log 2 / x; log 3;", V))
        self.assertEqual(p.outcome, "aborted")
        self.assertIn("division by zero", p.error)
        self.assertEqual(sim.logs, ["1"])
