"""PLUTO clauses of the Annex A grammar that procedures generated from the grammar found
missing (tests/host/test_pluto_annex_a.py), each with the meaning the standard gives it."""

import unittest

from obsw.pluto.checker import PlutoTypeError
from obsw.pluto.dryrun import dry_run
from obsw.pluto.interp import load
from obsw.pluto.lexer import PlutoSyntaxError
from obsw.pluto.parser import parse
from obsw.pluto.system import SimulatedSystem

SPEC = {
    "clock_start": "2025-01-01T00:00:00Z",
    "parameters": {
        "voltage of EPS": {"timeline": [[0, {"value": 7, "unit": "V"}], [5, 6.5]]},
        "mode of OBC": {"timeline": [[0, "SAFE"], [5, "NOMINAL"]]},
        "speed of Wheel 2": {"value": 3, "unit": "rad/s"},
    },
    "activities": {
        "heat of Heater 07": {"duration_s": 1},
        "run of Sequencer": {},
        "arm of Heater 07": {},
    },  # fmt: skip
    "events": [{"name": "Ready of OBC", "at_s": [3]}],
}


def step(main, decl=""):
    return (
        "procedure\ninitiate and confirm step S\n%s\nmain\n%s\nend main\nend step;\nend procedure"
        % ("declare %s end declare" % decl if decl else "", main)
    )


def main_body(proc):
    return proc[4][0][3][4]


class TestNames(unittest.TestCase):
    def test_words_after_the_first_may_be_digits(self):
        t = dry_run(step("log speed of Wheel 2; initiate and confirm heat of Heater 07;"), SPEC)
        self.assertEqual(t["log"], ["3 rad/s"])
        self.assertEqual(t["activity_calls"][0]["activity"], "heat of Heater 07")

    def test_a_digit_word_keeps_its_letters_and_zeros(self):
        body = main_body(parse(step("log x of Heater 2b of Rack 007;", "variable y of type real")))
        self.assertEqual(body[0][2][0][2], ("x", "Heater 2b", "Rack 007"))

    def test_digits_alone_are_still_numbers(self):
        t = dry_run(step("log 2 + 3, 1 min 30 s;"), SPEC)
        self.assertEqual(t["log"], ["590 s"])

    def test_a_step_without_main_takes_its_first_statement_from_the_name(self):
        # 'A B x := 1;': step 'A B' doing 'x := 1' (the longest name whose body can start)
        proc = parse("procedure initiate and confirm step A B x := 1; end step; end procedure")
        s = proc[4][0]
        self.assertEqual((s[2], s[3][4][0][0]), ("A B", "set"))


class TestObjectTypes(unittest.TestCase):
    def test_every_name_may_have_its_object_type(self):
        t = dry_run(step("log value of reporting data voltage of system element EPS,"
                         ' " ", parameter mode of system element OBC;'), SPEC)  # fmt: skip
        self.assertEqual(t["log"], ["7 V SAFE"])

    def test_operation_request_without_of(self):
        body = main_body(parse(step("open variable Valve with angle := 3 end with;")))
        self.assertEqual((body[0][0], body[0][2][2]), ("op", ("open", "Valve")))


class TestWaitSavesContext(unittest.TestCase):
    def test_values_saved_when_the_wait_ends(self):
        src = (
            'wait until mode of OBC = "NOMINAL" save context refer to voltage of EPS by v,'
            " to mode of OBC by m timeout 1 min; log v, m;"
        )
        t = dry_run(step(src), SPEC)
        self.assertEqual(t["log"], ["6.5 VNOMINAL"])

    def test_wait_for_event_saves_too(self):
        t = dry_run(step("wait for event Ready of OBC save context refer to mode of OBC by m;"
                         " log m;"), SPEC)  # fmt: skip
        self.assertEqual(t["log"], ["SAFE"])

    def test_saved_names_are_read_only(self):
        with self.assertRaises(PlutoTypeError):
            load(step("wait for 1 s save context refer to mode of OBC by m; m := 1;"),
                 SimulatedSystem(SPEC))  # fmt: skip


class TestWithin(unittest.TestCase):
    def test_units_after_the_tolerance(self):
        t = dry_run(step("log voltage of EPS within 100 mV of 7.05 V,"
                         " voltage of EPS within 10 [mV] of 7.05 V;"), SPEC)  # fmt: skip
        self.assertEqual(t["log"], ["TRUEFALSE"])

    def test_a_tolerance_is_a_number_with_units_once(self):
        for bad in ('"x"', "TRUE", "1 s V", "1 min mV"):
            with self.assertRaises(PlutoTypeError):
                load(step("log voltage of EPS within %s of 7 V;" % bad), SimulatedSystem(SPEC))


class TestPropertyRequestArguments(unittest.TestCase):
    def test_arguments_reach_the_system(self):
        t = dry_run(step("log voltage of EPS with channel := 2 end with;"), SPEC)
        self.assertEqual(t["status"], "aborted")
        self.assertIn("takes no arguments", t["runtime_error"])

    def test_only_system_properties_take_arguments(self):
        with self.assertRaises(PlutoTypeError) as c:
            load(step("x := 1; log x with 2 end with;", "variable x of type real"),
                 SimulatedSystem(SPEC))  # fmt: skip
        self.assertEqual(c.exception.msg,
                         "x takes no arguments: only a system object's property may")  # fmt: skip


class TestArgumentsThatAreReferences(unittest.TestCase):
    def test_activity_and_event_arguments(self):
        t = dry_run(step("initiate and confirm run of Sequencer with arguments activity arm of"
                         " Heater 07, activity heat of Heater 07 with arguments power := 2"
                         " end with, event Ready of OBC end with;"), SPEC)  # fmt: skip
        self.assertEqual(t["activity_calls"][0]["arguments"], {
            "arg1": "arm of Heater 07",
            "arg2": {"activity": "heat of Heater 07", "arguments": {"power": 2}},
            "arg3": "Ready of OBC"})  # fmt: skip

    def test_an_array_argument_or_a_reference_of_type_array(self):
        # 'array b' without 'end array' is the object b, of object type array
        body = main_body(parse(step("initiate run of Sequencer with arguments"
                                    " a array 1, 2 end array, array b end with;")))  # fmt: skip
        args = body[0][2][1]
        self.assertEqual((args[0][0], args[0][1][0], args[1][1][:4]),
                         ("a", "arr", ["r", args[1][1][1], ("b",), "array"]))  # fmt: skip


class TestTypes(unittest.TestCase):
    def test_property_data_type_and_value_set(self):
        src = step("v := voltage of EPS; w := 3; log v, w;",
                   "variable v of type same as value of voltage of EPS,"
                   " variable w of type value of current parameter")  # fmt: skip
        t = dry_run(src, SPEC)
        self.assertEqual((t["error"], t["log"]), (None, ["7 V3"]))

    def test_property_value_set_forms(self):
        for t in ("states of current parameter of mode 2", "parameter reference of mode 2 V",
                  "states of current system element", "modes of current of OBC"):  # fmt: skip
            proc = parse(step("log 1;", "variable x of type %s" % t))
            self.assertEqual(proc[4][0][3][2][0][3][0], "sys")

    def test_enumerated_set_of_an_object(self):
        proc = parse(step("x := 1;", "variable x of type modes of OBC"))
        self.assertEqual(proc[4][0][3][2][0][3][0], "sys")


class TestSyntaxErrors(unittest.TestCase):
    def test_still_refused(self):
        for bad in ("wait for 1 s save context refer to x;", "log x with end with;",
                    "log 1 within 2 V V2 of 3;", "log 1 in (1);"):  # fmt: skip
            with self.assertRaises(PlutoSyntaxError):
                parse(step(bad))


class TestSigns(unittest.TestCase):
    def test_a_sign_before_a_time_or_a_string_is_refused_not_a_crash(self):
        for bad in ("-2025-01-01T00:00:00Z", '+"x"', "-TRUE"):
            with self.assertRaises(PlutoTypeError):
                load(step("log %s;" % bad), SimulatedSystem(SPEC))
        with self.assertRaises(PlutoSyntaxError):
            parse(step("log 1 within -2025-01-01T00:00:00Z of 2;"))
