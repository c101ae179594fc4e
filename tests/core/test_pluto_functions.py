"""PLUTO standard functions (ECSS-E-ST-70-32C Annex C): every function with its semantics, names
of several words (``to string``, ``day of year``), and the errors they give."""

import unittest

from obsw.pluto.builtins import FUNCTIONS, MAX_NAME_WORDS
from obsw.pluto.checker import PlutoReferenceError, PlutoTypeError
from obsw.pluto.dryrun import dry_run
from obsw.pluto.interp import load
from obsw.pluto.parser import parse
from obsw.pluto.system import SimulatedSystem

START = "2025-01-01T00:00:00Z"


def step(main, decl=""):
    return (
        "procedure\ninitiate and confirm step S\n%s\nmain\n%s\nend main\nend step;\nend procedure"
        % ("declare %s end declare" % decl if decl else "", main)
    )


def logs(main, decl="", spec=None):
    spec = dict(spec or {})
    spec.setdefault("clock_start", START)
    t = dry_run(step(main, decl), spec)
    if not t["accept"]:
        raise AssertionError(t["error"])
    if t.get("runtime_error"):
        raise AssertionError(t["runtime_error"])
    return t["log"]


def value(expr):
    return logs("log %s;" % expr)[0]


class TestMathematical(unittest.TestCase):
    def test_abs_sqrt_exp_logarithms(self):
        self.assertEqual(value("abs(-2)"), "2")
        self.assertEqual(value("abs(-2.5 V)"), "2.5 V")
        self.assertEqual(value("sqrt(16)"), "4.0")
        self.assertEqual(value("sqrt(16 m^2)"), "4.0 m")
        self.assertEqual(value("exp(0)"), "1.0")
        self.assertEqual(value("ln(1)"), "0.0")
        # the interpreter's libm decides the last bit: 2.9999999999999996 with a board's
        # software log10, 3.0 with glibc
        self.assertTrue(abs(float(value("log(1000)")) - 3.0) < 1e-12)

    def test_trigonometry_takes_angles_in_any_unit(self):
        self.assertEqual(value("round(sin(90 deg) * 1000)"), "1000")
        self.assertEqual(value("round(cos(0 rad) * 1000)"), "1000")
        self.assertEqual(value("round(tan(45 deg) * 1000)"), "1000")
        self.assertEqual(value("round(arcsin(1) * 1000)"), "1571")
        self.assertEqual(value("round(arccos(1) * 1000)"), "0")
        self.assertEqual(value("round(arctan(1) * 1000)"), "785")
        self.assertEqual(value("round(arctan2(1, -1) * 1000)"), "2356")
        self.assertEqual(value("round(sinh(1) * 1000)"), "1175")
        self.assertEqual(value("round(cosh(1) * 1000)"), "1543")
        self.assertEqual(value("round(tanh(1) * 1000)"), "762")

    def test_rounding_keeps_units(self):
        self.assertEqual(value("round(2.5)"), "3")
        self.assertEqual(value("round(-2.5)"), "-3")
        self.assertEqual(value("trunc(-2.7 V)"), "-2 V")
        self.assertEqual(value("floor(-2.5)"), "-3")
        self.assertEqual(value("ceiling(2.1)"), "3")
        self.assertEqual(value("sign(-3 m)"), "-1")

    def test_min_max_compare_across_units(self):
        self.assertEqual(value("min(2 V, 900 mV, 1 V)"), "900 mV")
        self.assertEqual(value("max(1, 5, 3)"), "5")

    def test_domain_errors_abort_with_the_argument(self):
        t = dry_run(step("log sqrt(-1);"))
        self.assertEqual(t["status"], "aborted")
        self.assertIn("sqrt: argument -1 outside the function's domain", t["runtime_error"])
        t = dry_run(step("log ln(0);"))
        self.assertIn("ln: argument 0", t["runtime_error"])


class TestTime(unittest.TestCase):
    def test_current_time_and_calendar_fields(self):
        t = "2024-12-31T13:14:15Z"
        self.assertEqual(
            logs(
                "log to string(current time()); log year(%s), month(%s), day of month(%s);"
                " log day of year(%s), day of week(%s), hour(%s), minute(%s), second(%s);"
                % ((t,) * 8)
            ),
            ["2025-01-01T00:00:00.000Z", "20241231", "36621314" + "15"],
        )
        # a fraction of a second (near the epoch: exact in a board's single-precision float)
        self.assertEqual(value("second(1970-01-01T00:00:01.5Z)"), "1.5")
        self.assertEqual(value("day of week(1970-01-01T00:00:00Z)"), "4")  # a Thursday
        self.assertEqual(value("day of year(2025-03-01T00:00:00Z)"), "60")

    def test_conversions(self):
        self.assertEqual(value('to absolute time("2025-01-02T00:00:00Z") - current time()'),
                         "86400 s")  # fmt: skip
        self.assertEqual(value("seconds(2 min)"), "120")
        self.assertEqual(value("to relative time(90) + 1 min"), "150 s")
        t = dry_run(step('log to absolute time("tomorrow");'))
        self.assertIn("is no ISO 8601 time", t["runtime_error"])


class TestString(unittest.TestCase):
    def test_string_functions(self):
        self.assertEqual(value('length("abc")'), "3")
        self.assertEqual(value('substring("abcdef", 2, 3)'), "bcd")
        self.assertEqual(value('substring("abcdef", 4)'), "def")
        self.assertEqual(value('concatenate("a", "b", "c")'), "abc")
        self.assertEqual(value('index of("abcabc", "ca")'), "3")
        self.assertEqual(value('index of("abc", "x")'), "0")
        self.assertEqual(value('to upper case("Safe Mode")'), "SAFE MODE")
        self.assertEqual(value('to lower case("Safe Mode")'), "safe mode")
        self.assertEqual(value('trim("  x ")'), "x")

    def test_to_string_of_every_type(self):
        self.assertEqual(
            logs('log to string(3), "|", to string(2.5 V), "|", to string(TRUE), "|",'
                 ' to string(1 min), "|", to string("s");'),
            ["3|2.5 V|TRUE|1 min|s"],
        )  # fmt: skip

    def test_conversions_from_strings(self):
        self.assertEqual(value('to integer(" 42 ") + 1'), "43")
        self.assertEqual(value('to integer("0x1F")'), "31")
        self.assertEqual(value('to real("2.5") * 2'), "5.0")
        self.assertEqual(value('to Boolean("true")'), "TRUE")
        t = dry_run(step('log to integer("4x");'))
        self.assertIn("to integer: '4x' is no integer", t["runtime_error"])

    def test_results_are_typed_at_load(self):
        load(step('n := to integer("4"); s := to string(n); b := to Boolean("FALSE");',
                  "variable n of type signed integer, variable s of type string,"
                  " variable b of type Boolean"))  # fmt: skip
        with self.assertRaises(PlutoTypeError) as c:
            load(step("n := to string(4);", "variable n of type signed integer"))
        self.assertIn("cannot assign a string", c.exception.msg)


class TestNames(unittest.TestCase):
    def test_multi_word_names_parse_as_one_function(self):
        e = parse(step("log to string(current time());"))[4][0][3][4][0][2][0]
        self.assertEqual((e[0], e[2], e[3][0][2]), ("f", "to string", "current time"))

    def test_space_before_the_parenthesis(self):
        self.assertEqual(logs("log to string (1 + 1), day of year (2025-02-01T00:00:00Z);"),
                         ["232"])  # fmt: skip

    def test_identifiers_with_the_same_words_stay_references(self):
        spec = {
            "parameters": {"day of year of Clock": 12, "length of Boom": {"value": 2, "unit": "m"}}
        }
        sim = SimulatedSystem(spec)
        load(step('log day of year of Clock, length of Boom, length("ab");'), sim)
        self.assertEqual(logs("log day of year of Clock + 1, length of Boom;", spec=spec),
                         ["132 m"])  # fmt: skip
        self.assertEqual(logs("length := 4; log length, to string(length);",
                              "variable length of type signed integer"), ["44"])  # fmt: skip

    def test_longest_name_is_bounded(self):
        for name in FUNCTIONS:
            self.assertTrue(len(name.split()) <= MAX_NAME_WORDS)

    def test_unknown_function_and_wrong_arguments(self):
        with self.assertRaises(PlutoReferenceError) as c:
            load(step("log to text(1);"))
        self.assertIn("unknown function to text", c.exception.msg)
        with self.assertRaises(PlutoTypeError) as c:
            load(step("log length(3);"))
        self.assertEqual(c.exception.msg, "argument 1 of length, 3, is not a string")
        with self.assertRaises(PlutoTypeError) as c:
            load(step('log substring("abc", 1.5);'))
        self.assertIn("is not an integer without units", c.exception.msg)
        with self.assertRaises(PlutoTypeError) as c:
            load(step("log year(3);"))
        self.assertIn("is not an absolute time", c.exception.msg)
        with self.assertRaises(PlutoTypeError) as c:
            load(step("log sqrt(2 m);"))
        self.assertIn("unit m is not a square", c.exception.msg)
        with self.assertRaises(PlutoTypeError) as c:
            load(step("log to string(1, 2);"))
        self.assertIn("to string takes 1 arguments, got 2", c.exception.msg)


if __name__ == "__main__":
    unittest.main()
