"""PLUTO type errors name what they reject: the operands as written, both units or types, the
variable; at load time, and at run time where only the values show the mismatch."""

import unittest

from obsw.pluto.checker import PlutoTypeError
from obsw.pluto.interp import Procedure, load
from obsw.pluto.lexer import PlutoError
from obsw.pluto.signatures import closest_argument
from obsw.pluto.system import SimulatedSystem, run_virtual

SPEC = {"parameters": {"speed of Wheel": {"value": 5, "unit": "deg/s"}, "mode of OBC": "SAFE"}}


def step(main, decl=""):
    return (
        "procedure\ninitiate and confirm step S\n%s\nmain\n%s\nend main\nend step;\nend procedure"
        % ("declare %s end declare" % decl if decl else "", main)
    )


def rejected(main, decl=""):
    try:
        load(step(main, decl), SimulatedSystem(SPEC))
    except PlutoTypeError as e:
        return e.msg
    raise AssertionError("accepted " + main)


def run_error(main, decl=""):
    """The run-time error of a procedure loaded without a resolver (system types unknown)."""
    sim = SimulatedSystem(SPEC)
    p = Procedure(load(step(main, decl)), sim)
    p.start(0)
    run_virtual(p, sim)
    return p.error


class TestAtLoad(unittest.TestCase):
    def test_comparison_names_both_units_and_the_parameter(self):
        self.assertEqual(rejected("log speed of Wheel > 3 m;"),
                         "cannot compare speed of Wheel (deg/s) with 3 m: units deg/s and m"
                         " differ")  # fmt: skip

    def test_comparison_names_the_variable(self):
        self.assertEqual(
            rejected("log v = 3 m;", "variable v of type real with units deg/s"),
            "cannot compare v (deg/s) with 3 m: units deg/s and m differ",
        )
        self.assertEqual(
            rejected("log v between 1 V and 2 V;", "variable v of type real with units deg/s"),
            "cannot compare v (deg/s) with 1 V: units deg/s and V differ",
        )
        self.assertEqual(
            rejected("log v in (1 V, 2 deg/s);", "variable v of type real with units deg/s"),
            "cannot compare v (deg/s) with 1 V: units deg/s and V differ",
        )

    def test_comparison_of_types(self):
        self.assertEqual(rejected("log mode of OBC = 3;"),
                         "cannot compare mode of OBC (string) with 3: types string and integer"
                         " differ")  # fmt: skip

    def test_arithmetic_names_both_units(self):
        self.assertEqual(rejected("log speed of Wheel + 2 m/s;"),
                         "cannot add speed of Wheel (deg/s) and 2 m/s: units deg/s and m/s"
                         " differ")  # fmt: skip
        self.assertEqual(rejected("log 1 m - 2;"), "cannot subtract 1 m and 2: units m and"
                         " none differ")  # fmt: skip
        self.assertEqual(rejected('log "a" * 2;'), 'cannot apply * to "a" and 2')

    def test_compound_operands_in_si_units(self):
        self.assertEqual(
            rejected("log 2 m * 3 s > 1 V;"),
            "cannot compare 2 m * 3 s (m.s) with 1 V: units m.s and V differ",
        )

    def test_assignment_names_the_variable_and_both_units(self):
        self.assertEqual(rejected("v := 3 m;", "variable v of type real with units V"),
                         "v: cannot assign 3 m to a real variable with units V: units m and V"
                         " differ")  # fmt: skip
        self.assertEqual(rejected("v := speed of Wheel;", "variable v of type real with units V"),
                         "v: cannot assign speed of Wheel (deg/s) to a real variable with units"
                         " V: units deg/s and V differ")  # fmt: skip


class TestAtRunTime(unittest.TestCase):
    def test_comparison_shows_the_values(self):
        self.assertEqual(run_error("log speed of Wheel > 3 m;"),
                         "runtime error at line 5: cannot compare speed of Wheel (5 deg/s) with"
                         " 3 m: units deg/s and m differ")  # fmt: skip

    def test_arithmetic_shows_the_values(self):
        self.assertEqual(run_error("log speed of Wheel - 3 m;"),
                         "runtime error at line 5: cannot subtract speed of Wheel (5 deg/s) and"
                         " 3 m: units deg/s and m differ")  # fmt: skip


if __name__ == "__main__":
    unittest.main()


class TestNumbersWithoutUnits(unittest.TestCase):
    """A number without units is dimensionless: against a value with units it is refused at
    load time (it would silently take that value's units)."""

    SPEC = {"parameters": {"coil_temp of Magnetorquer": {"value": 21, "unit": "degC"},
                           "count of X": 3}}  # fmt: skip

    def rejected(self, main):
        try:
            load(step(main), SimulatedSystem(self.SPEC))
        except PlutoTypeError as e:
            return "%d:%d %s" % (e.line, e.col, e.msg)
        raise AssertionError("accepted " + main)

    def test_parameter_with_units_against_a_bare_number(self):
        self.assertEqual(
            self.rejected("wait until coil_temp of Magnetorquer < 1800;"),
            "5:38 cannot compare coil_temp of Magnetorquer (degC) with 1800: units degC and none"
            " differ (a number without units is dimensionless)",
        )

    def test_either_side_and_every_relation(self):
        for rel in ("1800 > coil_temp of Magnetorquer", "coil_temp of Magnetorquer between 0"
                    " and 50 degC", "coil_temp of Magnetorquer in (20 degC, 21)",
                    "count of X = 3 V"):  # fmt: skip
            self.assertIn(" none", self.rejected("log %s;" % rel))

    def test_with_units_loads(self):
        load(step("log coil_temp of Magnetorquer < 1800 mdegC, count of X > 2;"),
             SimulatedSystem(self.SPEC))  # fmt: skip


class TestMisspeltArgument(unittest.TestCase):
    SPEC = {
        "activities": {
            "take image of Camera": {
                "arguments": [
                    {"name": "Exposure Time", "type": "relative time"},
                    {"name": "gain", "type": "real"},
                ]
            }
        }
    }

    def errors(self, args):
        src = step("initiate and confirm take image of Camera with arguments %s end with;" % args)
        try:
            load(src, SimulatedSystem(self.SPEC))
        except PlutoError as e:
            return [x.msg for x in e.errors]
        raise AssertionError("accepted " + args)

    def test_the_wrong_name_with_the_closest_declared(self):
        self.assertEqual(self.errors("Exposure Tme := 10 ms, gain := 2.0"), [
            "activity take image of Camera has no argument Exposure Tme; did you mean Exposure"
            " Time? (takes: Exposure Time, gain)"])  # fmt: skip

    def test_no_guess_when_nothing_is_close(self):
        self.assertEqual(self.errors("shutter := 10 ms, gain := 2.0"), [
            "activity take image of Camera has no argument shutter (takes: Exposure Time, gain)",
            "activity take image of Camera needs argument Exposure Time (takes: Exposure Time,"
            " gain)"])  # fmt: skip

    def test_closest_ignores_spaces_underscores_and_case(self):
        self.assertEqual(closest_argument("Exposure_tme", ["gain", "Exposure Time"]),
                         "Exposure Time")  # fmt: skip
        self.assertIsNone(closest_argument("mode", ["limit"]))
