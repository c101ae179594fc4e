"""PLUTO lexer and engineering units: tokens, positions, literals, unit texts and arithmetic."""

import unittest

from obsw.pluto import units
from obsw.pluto.lexer import (
    ABST,
    DIGITS,
    NUM,
    OP,
    RELT,
    STR,
    WORD,
    PlutoSyntaxError,
    line_col,
    tokenize,
)


def kinds(src):
    return [(t[0], t[1]) for t in tokenize(src)[:-1]]


class TestLexer(unittest.TestCase):
    def test_words_numbers_strings_operators(self):
        self.assertEqual(
            kinds('x := 3.5e2 + 0x1F; log "a b"'),
            [(WORD, "x"), (OP, ":="), (NUM, 350.0), (OP, "+"), (NUM, 31), (OP, ";"),
             (WORD, "log"), (STR, "a b")],
        )  # fmt: skip

    def test_positions_are_line_and_column(self):
        toks = tokenize("procedure\n  main")
        self.assertEqual(line_col(toks[0][2]), (1, 1))
        self.assertEqual(line_col(toks[1][2]), (2, 3))

    def test_glued_units_split_from_numbers(self):
        self.assertEqual(kinds("10s"), [(DIGITS, "10"), (WORD, "s")])
        self.assertEqual(kinds("1d2h"), [(DIGITS, "1"), (WORD, "d"), (DIGITS, "2"), (WORD, "h")])
        self.assertEqual(kinds("5eV"), [(DIGITS, "5"), (WORD, "eV")])

    def test_digits_keep_their_text(self):
        # a run of digits is an integer or a word of a name ("Heater 07"): the parser decides
        self.assertEqual(kinds("Heater 07 1.5"), [(WORD, "Heater"), (DIGITS, "07"), (NUM, 1.5)])

    def test_absolute_and_colon_relative_times(self):
        t = tokenize("2025-01-01T00:01:00.500Z 1:02:03:04:5")
        self.assertEqual(t[0][0], ABST)
        self.assertEqual(t[0][1], 1735689660.5)
        self.assertEqual(t[1][0], RELT)
        self.assertEqual(t[1][1], 86400 + 2 * 3600 + 3 * 60 + 4 + 0.5)

    def test_day_of_year_form(self):
        t = tokenize("2025-032T00:00:00.0")
        self.assertEqual(t[0][1], units.parse_iso("2025-02-01T00:00:00Z"))

    def test_comments_skipped(self):
        self.assertEqual(kinds("a // note\nb"), [(WORD, "a"), (WORD, "b")])

    def test_unterminated_string_has_position(self):
        with self.assertRaises(PlutoSyntaxError) as cm:
            tokenize('log\n  "abc')
        self.assertEqual((cm.exception.line, cm.exception.col), (2, 3))

    def test_unexpected_character(self):
        with self.assertRaises(PlutoSyntaxError) as cm:
            tokenize("x := 1 $")
        self.assertEqual(cm.exception.col, 8)
        self.assertEqual(cm.exception.kind, "syntax_error")


class TestNonAsciiDigits(unittest.TestCase):
    def test_superscript_digit_is_a_syntax_error(self):
        # CPython's str.isdigit() accepts "\u00b2"; the lexer must not take it for a number
        with self.assertRaises(PlutoSyntaxError):
            tokenize("\u00b2")
        with self.assertRaises(PlutoSyntaxError):
            tokenize("x := 1\u00b2;")

    def test_isdigits_is_ascii_only(self):
        self.assertTrue(units.isdigits("0123456789"))
        self.assertFalse(units.isdigits(""))
        self.assertFalse(units.isdigits("\u00b2"))
        self.assertFalse(units.isdigits("1a"))


class TestNonAscii(unittest.TestCase):
    """The lexer reads UTF-8 octets: the same tokens and columns on both interpreters."""

    def test_strings_and_comments_keep_their_characters(self):
        toks = tokenize('log "\u00e9t\u00e9 \u2103" // \u00b0C\nx')
        self.assertEqual(toks[1][1], "\u00e9t\u00e9 \u2103")
        self.assertEqual(toks[2][:2], (WORD, "x"))

    def test_columns_count_characters(self):
        with self.assertRaises(PlutoSyntaxError) as cm:
            tokenize('log "\u00e9\u00e9" $')
        self.assertEqual((cm.exception.line, cm.exception.col), (1, 10))

    def test_letters_are_ascii_letters(self):
        # CPython's str.isalpha() takes "\u00e9"; MicroPython's does not: neither does PLUTO
        with self.assertRaises(PlutoSyntaxError) as cm:
            tokenize("caf\u00e9 := 1;")
        self.assertEqual(cm.exception.col, 4)

    def test_every_operator(self):
        ops = ":= ** <= >= != = < > + - * / ( ) , ; : [ ] . ^ %".split()
        self.assertEqual(kinds(" ".join(ops)), [(OP, o) for o in ops])
        self.assertEqual(kinds("a!=b"), [(WORD, "a"), (OP, "!="), (WORD, "b")])
        with self.assertRaises(PlutoSyntaxError):
            tokenize("a ! b")

    def test_escaped_quote(self):
        self.assertEqual(tokenize('"a\\"b"')[0][1], 'a"b')


class TestUnits(unittest.TestCase):
    def test_symbols_with_prefixes(self):
        self.assertEqual(units.symbol("km")[0], 1000)
        self.assertAlmostEqual(units.symbol("mV")[0], 0.001)
        self.assertEqual(units.symbol("KiB")[0], 8192)
        self.assertIsNone(units.symbol("kdeg"))  # deg takes submultiples only
        self.assertIsNone(units.symbol("foo"))

    def test_compound_units(self):
        s, d = units.parse("m.s^-2")
        self.assertEqual(d, (1, 0, -2, 0, 0, 0, 0, 0))
        s, d = units.parse("[km/h]")
        self.assertAlmostEqual(s, 1000 / 3600)
        with self.assertRaises(units.UnitError):
            units.parse("m/")

    def test_conversion_and_offset(self):
        self.assertAlmostEqual(units.Quantity(1500, "mV").to("V").value, 1.5)
        self.assertAlmostEqual(units.Quantity(0, "degC").to("K").value, 273.15)
        self.assertEqual(units.Quantity(2, "min").to("s").value, 120)
        with self.assertRaises(units.UnitError):
            units.Quantity(1, "V").to("s")

    def test_arithmetic(self):
        q = units.arith("+", units.Quantity(3, "V"), units.Quantity(500, "mV"))
        self.assertEqual((q.value, q.unit), (3.5, "V"))
        q = units.arith("/", units.Quantity(10, "m"), units.Quantity(2, "s"))
        self.assertEqual(units.dims(q.unit), (1, 0, -1, 0, 0, 0, 0, 0))
        self.assertEqual(units.arith("/", units.Quantity(1, "km"), units.Quantity(1, "m")), 1000)
        with self.assertRaises(units.UnitError):
            units.arith("+", units.Quantity(1, "V"), units.Quantity(1, "s"))

    def test_absolute_time_arithmetic(self):
        t = units.AbsTime(100)
        self.assertEqual(units.arith("+", t, units.Quantity(2, "min")).seconds, 220)
        d = units.arith("-", units.AbsTime(160), t)
        self.assertEqual((d.value, d.unit), (60, "s"))

    def test_iso_round_trip(self):
        for text in ("1970-01-01T00:00:00.000Z", "2024-02-29T23:59:59.250Z"):
            self.assertEqual(units.iso(units.parse_iso(text)), text)


class TestNotUnicode(unittest.TestCase):
    def test_a_lone_surrogate_is_a_syntax_error_with_its_place(self):
        # made at run time: a literal one would not freeze (the frozen image's strings are UTF-8)
        high, low = chr(0xD800), chr(0xDFFF)
        try:
            high.encode()
        except UnicodeError:
            pass
        else:  # MicroPython's strings cannot hold one
            return
        from obsw.pluto.interp import load

        for src, where in ((high, (1, 1)), ("procedure\n  x " + low, (2, 5))):
            with self.assertRaises(PlutoSyntaxError) as cm:
                load(src)
            self.assertEqual((cm.exception.line, cm.exception.col), where)
