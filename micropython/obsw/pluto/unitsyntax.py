"""PLUTO engineering units (Annex B) and predefined types as a procedure writes them."""

from obsw.pluto import units
from obsw.pluto.lexer import ABST, DIGITS, EOF, NUM, OP, RELT, STR, WORD, PlutoSyntaxError
from obsw.pluto.syntax import RESERVED, TokenParser, _show

_KINDS = (("system", "element"), ("reporting", "data"), ("parameter",), ("activity",), ("event",))
_TYPE_ENDS = ("of", "end", ",", "described", "with")


def _opens_constant(t, nt):
    """True when token ``t`` (``nt`` after it) starts a constant: '+ 2' does, '+ x' not."""
    if t[0] in (NUM, DIGITS, STR, ABST, RELT) or t[1] == "TRUE" or t[1] == "FALSE":
        return True
    return t[0] == OP and (t[1] == "+" or t[1] == "-") and nt[0] in (NUM, DIGITS, RELT)


class UnitTypeParser(TokenParser):
    """Units and types; ``constant`` comes from the expression parser."""

    def unit(self):
        """Engineering units written after a number or after 'with units', as text, or None."""
        t = self.toks[self.i]
        if t[0] == OP and t[1] == "[":
            j = self.i + 1
            parts = []
            while self.toks[j][0] != EOF and self.toks[j][1] != "]":
                parts.append(str(self.toks[j][1]))
                j += 1
            if self.toks[j][0] == EOF:
                self.err("expected ']' to close the units")
            text = "".join(parts)
            self.i = j + 1
        elif self._unit_start(self.i):
            start = self.i
            text = self._unit_ref()
            if text is None:
                self.i = start
                return None
        else:
            return None
        try:
            units.parse(text)
        except units.UnitError as e:
            self.err(str(e), t[2])
        return text

    # Annex B: <unit reference> = <product> ["/" <factor>]; <product> = <factor> {"." <factor>};
    # <factor> = (<simple unit> | "(" <unit reference> ")") ["^" <exponent>]; as text, or None
    # (the position then undefined) when the tokens here are no units
    def _unit_start(self, j):
        t = self.toks[j]
        if t[0] == OP and t[1] == "(":
            return self._unit_start(j + 1)
        return t[0] == WORD and t[1] not in RESERVED and units.symbol(t[1]) is not None

    def _unit_ref(self):
        text = self._unit_product()
        if text is not None and self.isop("/") and self._unit_start(self.i + 1):
            save = self.i
            self.i += 1
            f = self._unit_factor()
            if f is None:
                self.i = save  # '10 m / (x + 1)': a division
            else:
                text += "/" + f
        return text

    def _unit_product(self):
        text = self._unit_factor()
        while text is not None and self.isop(".") and self._unit_start(self.i + 1):
            self.i += 1
            f = self._unit_factor()
            if f is None:
                return None
            text += "." + f
        return text

    def _unit_factor(self):
        t = self.toks[self.i]
        if t[0] == OP and t[1] == "(":
            self.i += 1
            inner = self._unit_ref()
            if inner is None or not self.isop(")"):
                return None
            self.i += 1
            text = "(" + inner + ")"
        elif t[0] == WORD and t[1] not in RESERVED and units.symbol(t[1]) is not None:
            self.i += 1
            text = t[1]
        else:
            return None
        if self.isop("^"):
            e = self._unit_exponent()
            if e is None:
                self.err("expected an exponent after '^'")
            text += "^" + e
        return text

    def _unit_exponent(self):
        self.i += 1
        paren = self.isop("(")
        if paren:
            self.i += 1
        sign = ""
        if self.isop("-"):
            sign, self.i = "-", self.i + 1
        t = self.toks[self.i]
        if t[0] != DIGITS:
            return None
        self.i += 1
        if not paren:
            return sign + t[1]
        if not self.isop("/") or self.tok(1)[0] != DIGITS or self.tok(2)[1] != ")":
            return None
        d = self.tok(1)[1]
        self.i += 3
        return "(%s%s/%s)" % (sign, t[1], d)

    def typ(self):
        """A predefined type: 'b', 'i', 'u', 'r', 's', 'a', 'rt' or ('e', enumerated set name)."""
        for words, code in (
            (("Boolean",), "b"),
            (("signed", "integer"), "i"),
            (("unsigned", "integer"), "u"),
            (("integer",), "i"),
            (("real",), "r"),
            (("string",), "s"),
            (("absolute", "time"), "a"),
            (("relative", "time"), "rt"),
        ):
            start = self.i
            if self.take(*words):
                t = self.tok()
                if t[0] == DIGITS or t[0] == WORD and t[1] not in RESERVED:
                    self.i = start  # 'Boolean flags', a set named with the word: a name
                    break
                return code
        p = self.pos()
        if self.take("same", "as"):  # the data type of a system object's property
            return ("sys", p, "same as " + self.type_path(False))
        for words in _KINDS:
            if self.at(*words) and self.tok(len(words))[1] == "reference":
                self.i += len(words) + 1
                self.expect("of", after="after '%s reference'" % " ".join(words))
                return ("sys", p, "%s reference of %s" % (" ".join(words), self.type_path(True)))
        n = self.name("a type")
        if not self.at("of"):
            return ("e", n)
        self.i += 1  # the values a property of a system object may take
        return ("sys", p, n + " of " + self.type_path(False))

    def type_path(self, constant):
        """``<property> {of <property>} of (<reference> | [current] <kind> [of (<property>
        <constant> | <reference>)])`` as text: a constant may end the properties where
        ``constant`` ('<kind> reference of <property> <constant>') and those after a kind."""
        parts = []
        allow = constant
        while True:
            save = self.i
            current = self.take("current")
            k = self.kind(False)
            if k is not None and (current or not self._name_here()):
                parts.append(("current " if current else "") + k)
                allow = True
            else:  # a property or an object: 'current', a kind, are words of its name here
                self.i = save
                t = self.object_type()
                start = self.i
                n = self.name("a property or an object")
                nt = self.tok()
                opens = _opens_constant(nt, self.tok(1))
                if allow and nt[0] != EOF and nt[1] not in _TYPE_ENDS and not opens:
                    n = self.property_constant(start, n)
                parts.append((t + " " if t else "") + n)
                if allow and _opens_constant(self.tok(), self.tok(1)):
                    parts[-1] += " " + str(self.constant()[2])
                    return " of ".join(parts)  # a constant ends it
            if not self.take("of"):
                return " of ".join(parts)

    def _name_here(self):
        t = self.tok()
        return t[0] == WORD and t[1] not in RESERVED

    def property_constant(self, start, n):
        """'mode 2 V.s': the property mode and the constant 2 V.s when the constant reaches
        past the name read (else the name as read); the constant is left to be read."""
        end = self.i
        k = start + 1
        while k < end and self.toks[k][0] != DIGITS:
            k += 1
        if k == end:
            return n
        self.i = k
        try:
            self.constant()
        except PlutoSyntaxError:
            self.i = end
            return n
        if self.i <= end:
            self.i = end
            return n
        self.i = start
        return self.name("a property or an object", k - start)

    def kind(self, needed=True):
        for words in _KINDS:
            if self.take(*words):
                return " ".join(words)
        if needed:
            self.err("expected system element, reporting data, parameter, activity or event,"
                     " found %s" % _show(self.tok()))  # fmt: skip
        return None
