"""PLUTO parser: procedure structure, statements, expressions, precedence and syntax errors."""

import unittest

from obsw.pluto.exprs import ExprParser
from obsw.pluto.lexer import PlutoSyntaxError, tokenize
from obsw.pluto.parser import parse
from obsw.pluto.units import Quantity


def expr(text):
    p = ExprParser(tokenize(text))
    e = p.expr()
    return e


def shape(e):
    """Expression node as nested tuples without positions, for comparisons."""
    if isinstance(e, list):
        return ("ref",) + e[2]
    if e[0] == "c":
        v = e[2]
        return (v.value, v.unit) if isinstance(v, Quantity) else v
    if e[0] in ("b", "l", "cmp"):
        return (e[2], shape(e[3]), shape(e[4]))
    if e[0] == "u":
        return (e[2], shape(e[3]))
    if e[0] == "f":
        return ("call", e[2]) + tuple(shape(a) for a in e[3])
    return e[0]


def body(main, decl=""):
    return parse(
        "procedure main initiate and confirm step S %s main %s end main end step; end main"
        " end procedure" % (decl, main)
    )[4][0][3][4]


class TestExpressions(unittest.TestCase):
    def test_left_associative(self):
        self.assertEqual(
            shape(expr("a - b - c")), ("-", ("-", ("ref", "a"), ("ref", "b")), ("ref", "c"))
        )
        self.assertEqual(shape(expr("8 / 4 / 2")), ("/", ("/", 8, 4), 2))

    def test_precedence(self):
        self.assertEqual(shape(expr("1 + 2 * 3")), ("+", 1, ("*", 2, 3)))
        self.assertEqual(shape(expr("2 ** 3 ** 2")), ("**", 2, ("**", 3, 2)))
        self.assertEqual(
            shape(expr("a OR b AND c")), ("OR", ("ref", "a"), ("AND", ("ref", "b"), ("ref", "c")))
        )
        self.assertEqual(shape(expr("a = 1 XOR b")), ("XOR", ("=", ("ref", "a"), 1), ("ref", "b")))

    def test_not_binds_to_a_simple_factor(self):
        self.assertEqual(shape(expr("NOT (a > 1)")), ("NOT", (">", ("ref", "a"), 1)))

    def test_references_multi_word_and_of(self):
        self.assertEqual(
            shape(expr("value of battery voltage of EPS")),
            ("ref", "value", "battery voltage", "EPS"),
        )
        r = expr("parameter angle of SolarPanel")
        self.assertEqual((r[2], r[3]), (("angle", "SolarPanel"), "parameter"))

    def test_constants_with_units_and_times(self):
        self.assertEqual(shape(expr("3.3 V")), (3.3, "V"))
        self.assertEqual(shape(expr("9.81 m/s^2")), (9.81, "m/s^2"))
        self.assertEqual(shape(expr("5 [km/h]")), (5, "km/h"))
        self.assertEqual(shape(expr("1 min 30 s")), (90, "s"))
        self.assertEqual(shape(expr("1d2h")), (93600, "s"))
        self.assertEqual(shape(expr("-5")), -5)
        self.assertEqual(shape(expr("0xFF")), 255)

    def test_functions(self):
        self.assertEqual(shape(expr("max(1, 2) + current time()")),
                         ("+", ("call", "max", 1, 2), ("call", "current time")))  # fmt: skip

    def test_comparatives(self):
        self.assertEqual(expr("x between 1 and 5")[0], "btw")
        self.assertEqual(expr("x within 5 % of y")[4], True)
        self.assertEqual(len(expr("x in (1, 2, 3)")[3]), 3)

    def test_ask_user(self):
        e = expr('ask user ("go?" default "no") expect Boolean')
        self.assertEqual((e[0], e[4]), ("ask", "b"))


class TestStatements(unittest.TestCase):
    def test_procedure_bodies(self):
        d = parse(
            """procedure
            declare event E described by "e", event F end declare
            preconditions if TRUE then wait for 1 s end preconditions
            main log "x"; end main
            watchdog initiate and confirm step W preconditions wait for event E
              end preconditions main log "w"; end main end step; end watchdog
            confirmation if TRUE end confirmation
            end procedure"""
        )
        self.assertEqual([x[2] for x in d[2]], ["E", "F"])
        self.assertEqual([c[0] for c in d[3]], ["if", "wait"])
        self.assertEqual(d[4][0][0], "log")
        self.assertEqual(d[5][0][2], "W")
        self.assertEqual(d[6][0][0], "if")

    def test_main_keyword_optional(self):
        self.assertEqual(parse('procedure log "x"; end procedure')[4][0][0], "log")

    def test_step_declarations(self):
        d = parse(
            "procedure initiate and confirm step S declare variable v of type real with units mV,"
            ' enumerated Mode ("A", "B"), variable m of type Mode, event E end declare'
            " main v := 1 mV; end main end step; end procedure"
        )[4][0][3]
        self.assertEqual([x[0] for x in d[2]], ["var", "enum", "var", "event"])
        self.assertEqual(d[2][0][3:5], ("r", "mV"))
        self.assertEqual(d[2][2][3], ("e", "Mode"))

    def test_each_step_statement(self):
        b = body(
            "x := 1; if x = 1 then log 1; else log 2; end if;"
            " in case x is = 1: log 1; or is between 2 and 3 OR > 9: log 2;"
            " otherwise: log 3; end case;"
            " while x < 3 timeout 5 s raise event E do x := x + 1; end while;"
            " repeat x := x - 1; until x = 0 timeout 1 min;"
            " for x := 10 to 0 by -2 do log x; end for;"
            " wait for 2 s; wait until x = 1 timeout 3 s raise event E; wait for event E;"
            ' inform user "a", 1; switch on of Heater with level := 2 end with;'
            " in the context of EPS do log 1; end context;"
        )
        self.assertEqual(
            [s[0] for s in b],
            ["set", "if", "case", "while", "repeat", "for", "wait", "wait", "wait", "inform", "op",
             "ctx"],
        )  # fmt: skip
        self.assertEqual(b[3][3][1], "E")
        self.assertEqual(len(b[2][3]), 2)
        self.assertEqual([s[2] for s in b[6:9]], ["for", "until", "event"])

    def test_activities_arguments_and_continuation(self):
        b = body(
            "initiate and confirm set_state_bits of CpduN with arguments state := 0x05,"
            " record a := 1, b := 2 end record, bits array 1, 0 end array end with refer by Set1"
            " in case confirmed: resume; not confirmed: restart max times 3 raise event E;"
            " aborted: ask user; end case;"
            " initiate Switch on Heater with directives priority := 1 end with;"
        )
        call = b[0][2]
        self.assertEqual(call[0][2], ("set_state_bits", "CpduN"))
        self.assertEqual([a[0] for a in call[1]], ["state", None, "bits"])
        self.assertEqual(call[1][1][1][0], "rec")
        self.assertEqual(call[1][2][1][0], "arr")
        self.assertEqual(b[0][3], "Set1")
        cont = b[0][4]
        self.assertEqual(sorted(cont), ["aborted", "confirmed", "not confirmed"])
        self.assertEqual(cont["not confirmed"][0], "restart")
        self.assertEqual(cont["not confirmed"][4], "E")
        self.assertEqual(b[1][0], "init")
        self.assertEqual(b[1][2][2][0][0], "priority")

    def test_parallel(self):
        d = parse(
            "procedure in parallel until one completes initiate and confirm A;"
            " initiate and confirm step S main log 1; end main end step; end parallel;"
            " end procedure"
        )
        s = d[4][0]
        self.assertEqual((s[0], s[2], [b[0] for b in s[3]]), ("par", False, ["conf", "step"]))


class TestSyntaxErrors(unittest.TestCase):
    def error(self, src):
        with self.assertRaises(PlutoSyntaxError) as cm:
            parse(src)
        return cm.exception

    def test_missing_end_if(self):
        e = self.error("procedure initiate and confirm step S main\nif TRUE then log 1;\nend main"
                       " end step; end procedure")  # fmt: skip
        self.assertEqual(e.line, 3)
        self.assertIn("end", e.msg)

    def test_step_statement_in_procedure_main(self):
        e = self.error("procedure\n  x := 1;\nend procedure")
        self.assertEqual((e.line, e.col), (2, 3))
        self.assertIn("put", e.msg)

    def test_unknown_unit(self):
        e = self.error("procedure log 5 [furlong]; end procedure")
        self.assertIn("furlong", e.msg)

    def test_missing_semicolon(self):
        e = self.error('procedure log "a" log "b"; end procedure')
        self.assertEqual(e.col, 19)

    def test_trailing_text(self):
        self.assertIn("end of text", self.error("procedure log 1; end procedure x").msg)

    def test_parallel_needs_two_branches(self):
        self.assertIn("two", self.error(
            "procedure in parallel initiate and confirm A; end parallel;"
            " end procedure").msg)  # fmt: skip
