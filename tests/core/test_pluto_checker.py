"""PLUTO load-time checks: unknown references and type errors, each with line and column."""

import unittest

from obsw.pluto.checker import PlutoReferenceError, PlutoTypeError
from obsw.pluto.interp import Procedure, load
from obsw.pluto.system import SimulatedSystem, run_virtual

SYSTEM = SimulatedSystem(
    {
        "parameters": {
            "angle of SolarPanel": {"value": 1.5, "unit": "deg"},
            "mode of OBC": "SAFE",
        },
        "activities": {"set_state_bits of CpduN": {}},
        "events": ["Overheat of Thermal"],
    }
)


def step(main, decl=""):
    return (
        "procedure\ninitiate and confirm step S\n%s\nmain\n%s\nend main\nend step;\nend procedure"
        % ("declare %s end declare" % decl if decl else "", main)
    )


V = "variable x of type signed integer"


def deepest(make):
    """The deepest nesting of ``make(n)`` the loader takes (its MAX_NESTING)."""
    from obsw.pluto.lexer import PlutoSyntaxError

    n = 1
    while True:
        try:
            load(make(n + 1))
        except PlutoSyntaxError as e:
            if "nesting" not in e.msg:
                raise
            return n
        n += 1


def parens(n):
    return "(" * n + "x" + ")" * n


def ifs(n, body):
    return "if x > 0 then " * n + body + " end if;" * n


class TestNestingLimit(unittest.TestCase):
    """Whatever nesting the loader takes, the parser, the checker and the interpreter walk on
    a board's C stack (the Cortex-M stage runs this with the Pyboard's 15,360 bytes)."""

    def check(self, make):
        n = deepest(make)
        sim = SimulatedSystem()  # its clock starts at 0: exact on single-precision boards too
        p = Procedure(load(make(n)), sim)
        p.start(sim.now)
        run_virtual(p, sim)
        self.assertEqual((p.outcome, sim.logs), ("confirmed", ["7"]))
        return n

    def test_parentheses(self):
        self.assertTrue(self.check(lambda n: step("x := 7; log %s;" % parens(n), V)) >= 8)

    def test_blocks(self):
        self.assertTrue(self.check(lambda n: step("x := 7; " + ifs(n, "log x;"), V)) >= 8)

    def test_blocks_and_parentheses(self):
        self.check(lambda n: step("x := 7; " + ifs(n // 2, "log %s;" % parens(n - n // 2)), V))


class TestRejections(unittest.TestCase):
    def reject(self, src, cls, resolver=None, args=None):
        with self.assertRaises(cls) as cm:
            load(src, resolver, args)
        return cm.exception

    def test_unknown_variable_with_position(self):
        e = self.reject(step("log 1;\n  x := 2;"), PlutoReferenceError)
        self.assertEqual((e.kind, e.line, e.col), ("unknown_reference", 6, 3))

    def test_type_error_names_variable_and_declared_type(self):
        for decl, stmt, msg in (
            ("count of type signed integer", 'count := "x";',
             "count: cannot assign a string to a signed integer variable"),
            ("n of type unsigned integer", "n := 1.5;",
             "n: cannot assign a real to an unsigned integer variable"),
            ("b of type Boolean", "b := 3;", "b: cannot assign an integer to a Boolean variable"),
        ):  # fmt: skip
            e = self.reject(step(stmt, "variable " + decl), PlutoTypeError)
            self.assertEqual(e.msg, msg)

    def test_deep_nesting_is_a_syntax_error_with_line(self):
        from obsw.pluto.lexer import PlutoSyntaxError

        for src in (
            step("log " + "(" * 200 + "1" + ")" * 200 + ";"),
            step("if TRUE then " * 100 + "log 1;" + " end if;" * 100),
            step("log " + "9" * 5000 + ";"),
            step("log 2025-13-45T25:61:61Z;"),
            step("log 3:67:0.74.39:806:36.;"),
        ):
            e = self.reject(src, PlutoSyntaxError)
            self.assertTrue(e.line >= 1)

    def test_long_operator_chain_is_a_syntax_error_with_line(self):
        # deeper than any recursion limit: refused before anything walks the tree recursively
        from obsw.pluto.lexer import PlutoSyntaxError

        e = self.reject(step("log 1" + " + 1" * 3000 + ";"), PlutoSyntaxError)
        self.assertTrue(e.line >= 1)

    def test_unknown_event(self):
        e = self.reject(step("wait for 1 s timeout 1 s raise event Nope;"), PlutoReferenceError)
        self.assertIn("Nope", e.msg)

    def test_unknown_parameter_and_activity_with_resolver(self):
        e = self.reject(step("log tilt of SolarPanel;"), PlutoReferenceError, SYSTEM)
        self.assertIn("tilt of SolarPanel", e.msg)
        e = self.reject(step("initiate and confirm reset of CpduN;"), PlutoReferenceError, SYSTEM)
        self.assertIn("reset of CpduN", e.msg)
        e = self.reject(step("wait for event Fire of Thermal;"), PlutoReferenceError, SYSTEM)
        self.assertIn("Fire", e.msg)

    def test_unknown_function(self):
        self.reject(step("log frobnicate(1);"), PlutoReferenceError)

    def test_undeclared_loop_variable(self):
        self.reject(step("for i := 1 to 3 do log i; end for;"), PlutoReferenceError)

    def test_boolean_arithmetic(self):
        e = self.reject(step("log TRUE + 1;"), PlutoTypeError)
        self.assertEqual(e.kind, "type_error")
        self.assertEqual(e.line, 5)

    def test_units_mismatch(self):
        e = self.reject(step("log 1 V + 2 s;"), PlutoTypeError)
        self.assertIn("units", e.msg)

    def test_assignments(self):
        d = "variable v of type real with units V, variable n of type signed integer"
        self.reject(step('v := "high";', d), PlutoTypeError)
        self.reject(step("v := 5 s;", d), PlutoTypeError)
        self.reject(step("n := 1.5;", d), PlutoTypeError)
        load(step("v := 5 mV; n := 3; v := 2;", d))

    def test_assign_to_parameter(self):
        self.reject(step("angle of SolarPanel := 1;"), PlutoTypeError, SYSTEM)

    def test_conditions_must_be_boolean(self):
        self.reject(step("if 1 then log 1; end if;"), PlutoTypeError)
        self.reject(step("while 2 do log 1; end while;"), PlutoTypeError)
        self.reject(step("repeat log 1; until 3;"), PlutoTypeError)

    def test_waits_and_timeouts_need_times(self):
        self.reject(step("wait for 5;"), PlutoTypeError)
        self.reject(step('wait until "x";'), PlutoTypeError)
        self.reject(step("while TRUE timeout 3 V do log 1; end while;"), PlutoTypeError)
        load(step("wait for 5 s; wait until 2025-01-01T00:00:00Z; wait for 1:00:00:00;"))

    def test_function_arguments(self):
        self.reject(step("log sqrt(1, 2);"), PlutoTypeError)
        self.reject(step('log sqrt("a");'), PlutoTypeError)
        self.reject(step("log length(5);"), PlutoTypeError)

    def test_comparisons(self):
        self.reject(step('log 1 < "a";'), PlutoTypeError)
        self.reject(step("log 1 V = 2 s;"), PlutoTypeError)
        self.reject(step("log TRUE < FALSE;"), PlutoTypeError)

    def test_enumerated(self):
        d = 'enumerated Mode ("SAFE", "NOMINAL"), variable m of type Mode'
        self.reject(step('m := "OTHER";', d), PlutoTypeError)
        load(step('m := "SAFE";', d))

    def test_system_types_from_resolver(self):
        self.reject(step("log mode of OBC + 1;"), PlutoTypeError, SYSTEM)
        load(step("log angle of SolarPanel * 2;"), SYSTEM)

    def test_max_times_integer(self):
        self.reject(
            step("initiate and confirm X in case not confirmed: restart max times 1.5; end case;"),
            PlutoTypeError,
        )

    def test_all_errors_listed(self):
        with self.assertRaises(PlutoReferenceError) as cm:
            load(step("a := 1;\nb := 2;"))
        self.assertEqual([e.line for e in cm.exception.errors], [5, 6])

    def test_arguments_are_known(self):
        load(step("log level + 1;"), None, {"level": 3})
        self.reject(step('log level + "x";'), PlutoTypeError, None, {"level": 3})
