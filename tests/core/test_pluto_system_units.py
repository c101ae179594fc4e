"""The simulated system description: values with units wherever a value goes, times with units,
and descriptions it cannot play refused when read (never while a procedure runs)."""

import unittest

from obsw.pluto.dryrun import dry_run
from obsw.pluto.system import SimulatedSystem, SystemSpecError
from obsw.pluto.units import Quantity

# the clock starts at 0 where procedures wait: a board's single-precision floats cannot
# step a 2025 epoch clock by a second
START = "1970-01-01T00:00:00Z"


def step(main, decl=""):
    return (
        "procedure\ninitiate and confirm step S\n%s\nmain\n%s\nend main\nend step;\nend procedure"
        % ("declare %s end declare" % decl if decl else "", main)
    )


def q(v, u):
    return {"value": v, "unit": u}


class TestValuesWithUnits(unittest.TestCase):
    def test_timeline_of_values_with_units(self):
        spec = {
            "clock_start": START,
            "parameters": {
                # kV and V: a factor exact in a board's single-precision floats too
                "bus voltage of EPS": {"timeline": [[0, q(6.5, "kV")], [5, q(7500, "V")]]}
            },
        }
        t = dry_run(
            step("log bus voltage of EPS; wait until bus voltage of EPS > 7000 V"
                 " timeout 10 s; log bus voltage of EPS;"), spec)  # fmt: skip
        self.assertEqual((t["status"], t["log"]), ("confirmed", ["6.5 kV", "7.5 kV"]))
        self.assertEqual(t["end_time_s"], 5)

    def test_values_converted_to_the_parameters_unit(self):
        line = [[0, 20], [1, q(300, "K")]]
        sim = SimulatedSystem({"parameters": {"t of Thermal": {"unit": "degC", "timeline": line}}})
        self.assertEqual(sim.describe("t of Thermal"), ("parameter", "i", "degC"))
        self.assertEqual(sim.get("t of Thermal"), Quantity(20, "degC"))
        sim.now = 1
        v = sim.get("t of Thermal")
        self.assertEqual(v.unit, "degC")
        self.assertAlmostEqual(v.value, 26.85, delta=1e-4)

    def test_value_with_units_as_a_plain_parameter(self):
        sim = SimulatedSystem({"parameters": {"rate of Wheel": q(2.5, "deg/s")}})
        self.assertEqual(sim.describe("rate of Wheel"), ("parameter", "r", "deg/s"))
        self.assertEqual(sim.get("rate of Wheel"), Quantity(2.5, "deg/s"))
        t = dry_run(
            step("log rate of Wheel > 1 deg/s;"),
            {"parameters": {"rate of Wheel": q(2.5, "deg/s")}},
        )
        self.assertEqual(t["log"], ["TRUE"])

    def test_times_with_units(self):
        spec = {
            "clock_start": START,
            "parameters": {"mode of OBC": {"timeline": [[0, "SAFE"], [q(2, "min"), "NOMINAL"]]}},
            "activities": {"warm up of Heater": {"duration_s": q(1, "min")}},
            "events": [{"name": "Overheat of Thermal", "at_s": [q(3, "min")]}],
        }
        t = dry_run(
            step('initiate and confirm warm up of Heater; log current time();'
                 ' wait until mode of OBC = "NOMINAL"; log current time();'
                 " wait for event Overheat of Thermal; log current time();"), spec)  # fmt: skip
        self.assertEqual(
            t["log"],
            ["1970-01-01T00:01:00.000Z", "1970-01-01T00:02:00.000Z", "1970-01-01T00:03:00.000Z"],
        )

    def test_answers_with_units(self):
        spec = {"clock_start": START, "user_responses": [q(2, "min")]}
        t = dry_run(step('r := ask user ("pause?") expect real; log r;',
                         "variable r of type real with units s"), spec)  # fmt: skip
        self.assertEqual(t["log"], ["120.0 s"])


class TestRefused(unittest.TestCase):
    def refused(self, spec, *words):
        with self.assertRaises(SystemSpecError) as c:
            SimulatedSystem(spec)
        for w in words:
            self.assertIn(w, str(c.exception))

    def test_units_that_do_not_agree(self):
        self.refused(
            {"parameters": {"v of EPS": {"timeline": [[0, q(1, "V")], [1, q(2, "m")]]}}},
            "parameter v of EPS at 1 s", "2 m is not in units of V",
        )  # fmt: skip
        self.refused({"parameters": {"v of EPS": q(1, "furlong")}}, "v of EPS", "furlong")
        self.refused({"parameters": {"v of EPS": q("x", "V")}}, "only numbers take units")
        self.refused({"parameters": {"v of EPS": {"value": 1, "units": "V"}}},
                     "v of EPS")  # fmt: skip

    def test_times_that_are_no_times(self):
        self.refused({"activities": {"a of B": {"duration_s": q(2, "V")}}},
                     "activity a of B, duration_s", "not a relative time")  # fmt: skip
        self.refused({"events": [{"name": "e of B", "at_s": ["soon"]}]}, "event e of B")
        self.refused({"parameters": {"p of B": {"timeline": [[0]]}}}, "timeline entry 0")
        self.refused({"parameters": {"p of B": {"timeline": []}}}, "list of [time, value]")
        self.refused({"clock_start": "yesterday"}, "clock_start")

    def test_cli_reports_the_file(self):
        self.refused({"activities": {"a of B": {"arguments": [{"type": "real"}]}}},
                     "activity a of B", "an argument is")  # fmt: skip
        self.refused([], "JSON object")


if __name__ == "__main__":
    unittest.main()
