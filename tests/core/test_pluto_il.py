"""PLUTO on the interaction layer: parameter reads, operations confirmed, not confirmed and
aborted, events counted, names resolved from interfaces and the spacecraft database; IL
nodes in one process on a simulated clock."""

import unittest

from obsw.il.clock import SimClock
from obsw.il.errors import ComponentError
from obsw.il.interface import (
    CONFIGURATION,
    DATA,
    INFO,
    Attribute,
    Event,
    Interface,
    Operation,
)
from obsw.il.loopback import resolver_for
from obsw.il.node import Node
from obsw.pluto.il_system import ActivityArgumentError, IlSystem
from obsw.pluto.interp import Procedure, load
from obsw.pluto.lexer import PlutoError
from obsw.pluto.names import Catalog, ParameterError, target_of, type_code
from obsw.pluto.units import Quantity

T0 = 1735689600.0  # 2025-01-01T00:00:00Z

PANEL = Interface(
    "SolarPanel",
    0x50,
    [
        Attribute("angle", 1, DATA, type="f32", unit="deg"),
        Attribute("mode", 2, CONFIGURATION, type="str"),
        Attribute("is_deployed", 3, DATA, type="bool"),
        Operation("set_angle", 4, ("angle",)),
        Operation("deploy", 5, (), asynchronous=True),
        Operation("crash", 6, ()),
        Event("angle_reached", 7, INFO),
    ],
)

CPDU = Interface(
    "CpduN",
    0x51,
    [
        Attribute("state", 1, DATA, type="uint8"),
        Operation("set_state_bits", 2, ("state", "mask")),
    ],
)


class Panel:
    def __init__(self):
        self.angle = 0.0
        self.mode = "SAFE"
        self.is_deployed = False
        self.il = None
        self.jobs = []
        self.finish_deploy = True

    def il_bind(self, provider):
        self.il = provider

    def set_angle(self, angle):
        if not -90 <= angle <= 90:
            raise ComponentError("ANGLE_OUT_OF_RANGE", "angle %s beyond the limit" % angle)
        self.il.update("angle", float(angle))
        self.il.emit("angle_reached", {"angle": angle})
        return self.angle

    def deploy(self, job):
        self.jobs.append(job)
        if self.finish_deploy:
            job.update("hinge 1")
            self.il.update("is_deployed", True)
            job.succeed("deployed")

    def crash(self):
        raise ValueError("hinge motor fault")


class Cpdu:
    def __init__(self):
        self.state = 0
        self.calls = []

    def set_state_bits(self, state, mask):
        self.calls.append((state, mask))
        self.state = state & mask
        return self.state


def procedure(main, decl=""):
    return (
        "procedure main initiate and confirm step S %s main %s end main end step; "
        "end main end procedure" % ("declare %s end declare" % decl if decl else "", main)
    )


class World:
    """One node with the panel and the CPDU, a procedure driven on simulated time."""

    def __init__(self, **options):
        self.clock = SimClock(T0)
        self.node = Node("obc", self.clock)
        self.panel = Panel()
        self.cpdu = Cpdu()
        self.node.provide(PANEL, self.panel)
        self.node.provide(CPDU, self.cpdu)
        self.out = []
        options.setdefault("timeout", 0.5)
        options.setdefault("activity_timeout", 10.0)
        self.system = IlSystem(
            self.node, on_output=lambda k, t: self.out.append((k, t)), **options
        )

    def run(self, src, arguments=None, limit_s=100):
        p = Procedure(load(src, self.system, arguments), self.system, arguments, poll=0.5)
        p.start(self.clock.now())
        drive(p, self.node, self.clock, limit_s)
        return p

    def logs(self):
        return [t for k, t in self.out if k == "log"]


def drive(proc, node, clock, limit_s=100):
    end = clock.now() + limit_s
    for _ in range(2000):
        node.poll()
        w = proc.run(clock.now())
        if proc.state != "running" or w is None or w.deadline is None:
            return
        if w.deadline > clock.now():
            if w.deadline > end:
                return
            clock.advance(w.deadline - clock.now())


class TestNames(unittest.TestCase):
    def test_type_codes(self):
        got = [type_code(t) for t in ("float32", "f32", "uint8", "u16", "int32", "bool",
                                      "string", "enum8", None, [5, 1], [3, 12])]  # fmt: skip
        self.assertEqual(got, ["r", "r", "i", "i", "i", "b", "s", "?", "?", "r", "i"])

    def test_paths_without_catalog(self):
        self.assertEqual(target_of("angle of SolarPanel"), ("SolarPanel", "angle"))
        self.assertEqual(target_of("value of angle of SolarPanel"), ("SolarPanel", "angle"))
        self.assertEqual(target_of("set state bits of CpduN"), ("CpduN", "set_state_bits"))
        self.assertEqual(target_of("voltage of Bus A of EPS"), ("EPSBusA", "voltage"))
        with self.assertRaises(ParameterError):
            target_of("Switch on Star Tracker1")

    def test_describe_from_local_interfaces(self):
        w = World()
        d = w.system.describe
        self.assertEqual(d("angle of SolarPanel"), ("parameter", "r", "deg"))
        self.assertEqual(d("value of angle of SolarPanel"), ("parameter", "r", "deg"))
        self.assertEqual(d("is_deployed of SolarPanel"), ("parameter", "b", None))
        self.assertEqual(d("set_angle of SolarPanel"), ("activity", None, None))
        self.assertEqual(d("angle_reached of SolarPanel"), ("event", None, None))
        self.assertIsNone(d("tilt of SolarPanel"))
        self.assertIsNone(d("angle of Moon"))

    def test_multi_word_names_match_any_spelling(self):
        w = World()
        self.assertEqual(w.system.describe("set state bits of Cpdu N"), ("activity", None, None))
        self.assertEqual(w.system.target("set state bits of Cpdu N"), "CpduN.set_state_bits")
        self.assertEqual(w.system.target("Is Deployed of solar panel"), "SolarPanel.is_deployed")

    def test_single_name_activity(self):
        cat = Catalog(interfaces=[Interface("StarTracker1", 9, [Operation("Switch_on", 1)])])
        self.assertEqual(cat.find("Switch on Star Tracker1")[1:3], ["StarTracker1", "Switch_on"])

    def test_describe_from_sdb_document(self):
        sdb = {
            "components": [
                {
                    "name": "EPS",
                    "attributes": [{"name": "battery voltage", "parameter": 1,
                                    "type": "float32", "unit": "V"},
                                   {"name": "mode", "parameter": 2, "type": "enum8"},
                                   {"name": "odd", "parameter": 3, "type": "uint8",
                                    "unit": "not a unit"}],
                    "operations": [{"name": "set_limit",
                                    "arguments": [{"name": "limit", "unit": "mV"}]}],
                    "events": [{"name": "undervoltage", "id": 1}],
                }
            ]
        }  # fmt: skip
        s = IlSystem(Node("n", SimClock(T0)), sdb)
        self.assertEqual(s.describe("battery voltage of EPS"), ("parameter", "r", "V"))
        self.assertEqual(s.describe("mode of EPS"), ("parameter", "?", None))
        self.assertEqual(s.describe("odd of EPS"), ("parameter", "i", None))
        self.assertEqual(s.describe("set limit of EPS"), ("activity", None, None))
        self.assertEqual(s.describe("undervoltage of EPS"), ("event", None, None))
        args = s.arguments("set limit of EPS", {"limit": Quantity(7.2, "V")})
        self.assertEqual(len(args), 1)
        self.assertAlmostEqual(args[0], 7200)

    def test_describe_from_sdb_object_and_interface(self):
        from obsw.pus.sdb import Sdb

        sdb = Sdb(
            {
                "components": [
                    {
                        "name": "SolarPanel",
                        "attributes": [
                            {"name": "angle", "parameter": 1, "type": "float32", "unit": "deg"}
                        ],
                        "events": [{"name": "angle_reached", "id": 1}],
                    }
                ]
            }
        )
        s = IlSystem(Node("n", SimClock(T0)), sdb, [PANEL])
        self.assertEqual(s.describe("angle of SolarPanel"), ("parameter", "r", "deg"))
        self.assertEqual(s.describe("angle_reached of SolarPanel"), ("event", None, None))
        # operations come from the interface; argument units from the same-named attribute
        self.assertEqual(s.arguments("set_angle of SolarPanel", {"arg1": Quantity(1, "rad")}),
                         (57.29577951308232,))  # fmt: skip

    def test_unknown_reference_rejected_at_load(self):
        w = World()
        with self.assertRaises(PlutoError) as c:
            load(procedure("log tilt of SolarPanel;"), w.system)
        self.assertEqual((c.exception.kind, c.exception.line), ("unknown_reference", 1))
        with self.assertRaises(PlutoError) as c:
            load(procedure("initiate and confirm turn of SolarPanel;"), w.system)
        self.assertIn("turn of SolarPanel", c.exception.msg)
        with self.assertRaises(PlutoError) as c:
            load(procedure("v := mode of SolarPanel;", "variable v of type real"), w.system)
        self.assertEqual(c.exception.kind, "type_error")


class TestParameters(unittest.TestCase):
    def test_reads_with_units(self):
        w = World()
        w.panel.angle = 12.5
        p = w.run(procedure(
            "log angle of SolarPanel; log value of angle of SolarPanel + 1 deg;"
            " log mode of SolarPanel; if is_deployed of SolarPanel then log 1; else log 0;"
            " end if;"))  # fmt: skip
        self.assertEqual(p.outcome, "confirmed")
        self.assertEqual(w.logs(), ["12.5 deg", "13.5 deg", "SAFE", "0"])
        self.assertEqual(w.system.reads, 4)

    def test_wait_until_parameter(self):
        w = World()
        w.clock.call_later(7, lambda: w.node.set("SolarPanel.mode", "SUN", timeout=1))
        p = w.run(procedure('wait until mode of SolarPanel = "SUN" timeout 20 s; log 1;'))
        self.assertEqual((p.outcome, w.logs()), ("confirmed", ["1"]))
        self.assertAlmostEqual(w.clock.now() - T0, 7, 0)

    def test_unreadable_parameter_aborts(self):
        w = World()
        w.system.catalog.add("parameter", "Moon", "phase", "r", None)
        p = w.run(procedure("log phase of Moon; log 2;"))
        self.assertEqual(p.outcome, "aborted")
        self.assertIn("cannot read phase of Moon", p.error)
        self.assertEqual(w.logs(), [])  # the abort is in the status, not in the log

    def test_reads_across_a_link(self):
        clock = SimClock(T0)
        eq = Node("equipment", clock)
        panel = Panel()
        panel.angle = 3.0
        eq.provide(PANEL, panel)
        obc = Node("obc", clock)
        obc.registry.resolver = resolver_for(obc, lambda: [eq], codec=True)
        out = []
        s = IlSystem(obc, None, [PANEL], timeout=1.0, on_output=lambda k, t: out.append(t))
        p = Procedure(load(procedure(
            "log angle of SolarPanel; initiate and confirm deploy of SolarPanel;"
            " initiate and confirm set_angle of SolarPanel with arguments angle := 45 deg"
            " end with; log angle of SolarPanel;"), s), s)  # fmt: skip
        p.start(T0)
        drive(p, obc, clock)
        self.assertEqual((p.outcome, out), ("confirmed", ["3.0 deg", "45.0 deg"]))
        self.assertEqual(panel.angle, 45.0)


class TestActivities(unittest.TestCase):
    def test_confirmed_with_converted_arguments(self):
        w = World()
        p = w.run(procedure(
            "initiate and confirm deploy of SolarPanel;"
            " initiate and confirm set_angle of SolarPanel with arguments angle := 0.5 rad"
            " end with; log angle of SolarPanel;"))  # fmt: skip
        self.assertEqual(p.outcome, "confirmed")
        self.assertAlmostEqual(w.panel.angle, 28.64788975654116)
        self.assertEqual(w.system.initiated, 2)

    def test_arguments_by_name_or_position(self):
        w = World()
        p = w.run(procedure(
            "initiate and confirm set state bits of Cpdu N with arguments mask := 0xFF,"
            " state := 0x05 end with; initiate and confirm set_state_bits of CpduN"
            " with arguments 6, 0x0F end with;"))  # fmt: skip
        self.assertEqual(p.outcome, "confirmed")
        self.assertEqual(w.cpdu.calls, [(5, 255), (6, 15)])

    def test_arguments_of_unknown_parameters_in_order(self):
        w = World()
        w.system.catalog.add("activity", "Heater", "heat")
        args = {"b": 3, "arg2": 2, "a": Quantity(1, "V"), "arg1": 1, "directives": {"x": 1}}
        self.assertEqual(w.system.arguments("heat of Heater", args), (1, 2, 1, 3))

    def test_argument_mismatch_aborts(self):
        w = World()
        with self.assertRaises(ActivityArgumentError):
            w.system.arguments("set_state_bits of CpduN", {"state": 1})
        with self.assertRaises(ActivityArgumentError):
            w.system.arguments("set_state_bits of CpduN", {"state": 1, "mask": 2, "gain": 3})
        p = w.run(procedure("initiate and confirm set_state_bits of CpduN with arguments"
                            " state := 1 end with;"))  # fmt: skip
        self.assertEqual(p.outcome, "aborted")
        self.assertIn("needs argument mask", p.error)
        self.assertEqual(w.cpdu.calls, [])

    def test_component_error_is_not_confirmed(self):
        w = World()
        p = w.run(procedure(
            "initiate and confirm set_angle of SolarPanel with arguments angle := 120 deg"
            " end with in case not confirmed: raise event Refused; end case; log 2;",
            "event Refused"))  # fmt: skip
        self.assertEqual(p.outcome, "confirmed")
        self.assertIn(("raise", "Refused"), w.out)
        self.assertEqual(
            w.logs()[0],
            "set_angle of SolarPanel not confirmed: ComponentError ANGLE_OUT_OF_RANGE:"
            " angle 120 beyond the limit",
        )
        self.assertEqual(w.logs()[1], "2")

    def test_not_confirmed_aborts_by_default(self):
        w = World()
        p = w.run(procedure("initiate and confirm set_angle of SolarPanel with arguments"
                            " angle := -100 deg end with; log 2;"))  # fmt: skip
        self.assertEqual((p.outcome, p.step_status["S"]), ("aborted", "aborted"))

    def test_provider_failure_is_aborted(self):
        w = World()
        p = w.run(procedure("initiate and confirm crash of SolarPanel in case aborted:"
                            " continue; end case; log 2;"))  # fmt: skip
        self.assertEqual(p.outcome, "confirmed")
        self.assertIn("crash of SolarPanel aborted: ProviderError", w.logs()[0])
        self.assertIn("hinge motor fault", w.logs()[0])

    def test_missing_provider_is_aborted(self):
        w = World()
        w.system.catalog.add("activity", "Heater", "heat", params=[])
        p = w.run(procedure("initiate and confirm heat of Heater in case aborted: continue;"
                            " end case; log 2;"))  # fmt: skip
        self.assertEqual(p.outcome, "confirmed")
        self.assertIn("heat of Heater aborted: UnavailableError", w.logs()[0])

    def test_no_outcome_within_timeout_is_aborted(self):
        w = World(activity_timeout=8.0)
        w.panel.finish_deploy = False
        p = w.run(procedure("initiate and confirm deploy of SolarPanel in case aborted:"
                            " raise event Late; end case;", "event Late"))  # fmt: skip
        self.assertEqual(p.outcome, "confirmed")
        self.assertEqual(w.logs(), ["deploy of SolarPanel aborted: no outcome within 8.0s"])
        self.assertAlmostEqual(w.clock.now() - T0, 8, 0)
        self.assertEqual(len(w.panel.jobs), 1)

    def test_late_outcome_of_asynchronous_operation(self):
        w = World()
        w.panel.finish_deploy = False
        w.clock.call_later(3, lambda: w.panel.jobs[0].succeed("late"))
        p = w.run(procedure("initiate deploy of SolarPanel refer by D; log D;"
                            " wait until D = \"confirmed\" timeout 5 s; log D;"))  # fmt: skip
        self.assertEqual((p.outcome, w.logs()), ("confirmed", ["executing", "confirmed"]))

    def test_abandoned_activity_is_aborted(self):
        w = World()
        w.panel.finish_deploy = False
        p = w.run(procedure(
            "in parallel until one completes initiate and confirm deploy of SolarPanel;"
            " initiate and confirm step T main wait for 2 s; end main end step;"
            " end parallel; log 1;"))  # fmt: skip
        self.assertEqual((p.outcome, w.logs()), ("confirmed", ["1"]))
        self.assertEqual(w.clock.now() - T0, 2)


class TestEvents(unittest.TestCase):
    def test_wait_for_event_counts_publications(self):
        w = World()
        w.clock.call_later(4, lambda: w.panel.set_angle(10))
        p = w.run(procedure("wait for event angle_reached of SolarPanel timeout 10 s; log 1;"))
        self.assertEqual((p.outcome, w.logs()), ("confirmed", ["1"]))
        self.assertEqual(w.clock.now() - T0, 4)
        self.assertEqual(w.system.event_count("angle_reached of SolarPanel"), 1)
        w.panel.set_angle(11)
        w.panel.set_angle(12)
        self.assertEqual(w.system.event_count("angle_reached of SolarPanel"), 3)

    def test_event_timeout(self):
        w = World()
        p = w.run(procedure("wait for event angle_reached of SolarPanel timeout 3 s raise"
                            " event Late;", "event Late"))  # fmt: skip
        self.assertEqual((p.outcome, p.step_status["S"]), ("aborted", "not confirmed"))
        self.assertIn(("raise", "Late"), w.out)

    def test_events_shared_by_forks_and_wake_up(self):
        w = World()
        woke = []
        w.system.on_wake = lambda: woke.append(1)
        other = w.system.fork()
        self.assertEqual(other.event_count("angle_reached of SolarPanel"), 0)
        w.panel.set_angle(5)
        self.assertEqual(w.system.event_count("angle_reached of SolarPanel"), 1)
        self.assertEqual(woke, [1])
        w.system.close()
        w.panel.set_angle(6)
        self.assertEqual(other.event_count("angle_reached of SolarPanel"), 0)

    def test_unknown_event_source_retries_later(self):
        w = World()
        s = w.system
        self.assertEqual(s.event_count("ready of Camera"), 0)
        c = s._events["Camera.ready"]
        self.assertIsNone(c.sub)
        self.assertIsNotNone(c.retry_at)

    def test_outputs(self):
        w = World()
        w.run(procedure('log "a"; inform user "b"; initiate and confirm set_angle of'
                        " SolarPanel with arguments 1 end with in case confirmed: raise event E;"
                        " end case;", "event E"))  # fmt: skip
        self.assertEqual(w.out, [("log", "a"), ("inform", "b"), ("raise", "E")])
        self.assertIsNone(w.system.ask_user("q?"))
        self.assertEqual(w.out[-1], ("ask", "q?"))


if __name__ == "__main__":
    unittest.main()
