"""PLUTO expression parser: token helpers, names, references, constants with units, operators."""

from obsw.pluto import units
from obsw.pluto.builtins import FIRST_WORDS, FUNCTIONS, MAX_NAME_WORDS
from obsw.pluto.lexer import (
    ABST,
    DIGITS,
    EOF,
    NUM,
    OP,
    RELT,
    STR,
    WORD,
    PlutoSyntaxError,
    line_col,
)

# Words that end a multi-word name: every keyword that may follow a name or open a statement.
RESERVED = set(
    (
        "of with end then do to by is and or timeout raise refer default expect described"
        " until else otherwise in initiate if while for repeat wait log inform main watchdog"
        " confirmation preconditions declare step procedure event variable enumerated between"
        " within ask record array AND OR XOR NOT TRUE FALSE"
    ).split()
)
# Annex A's object types, longest first; a reference may name one before each of its names.
OBJECT_TYPES = (
    ("predefined", "value", "set"),
    ("activity", "statement"),
    ("system", "element"),
    ("reporting", "data"),
    ("variable",),
    ("parameter",),
    ("argument",),
    ("activity",),
    ("event",),
    ("step",),
    ("record",),
    ("array",),
)
_KINDS = (("system", "element"), ("reporting", "data"), ("parameter",), ("activity",), ("event",))
_TYPE_ENDS = ("of", "end", ",", "described", "with")
_TYPE_FIRST = ("predefined", "activity", "system", "reporting", "variable", "parameter",
               "argument", "event", "step", "record", "array")  # fmt: skip
RELOPS = ("=", "!=", "<", ">", "<=", ">=")
_LOGIC = {"OR": 1, "XOR": 2, "AND": 3}
_ARITH = {"+": 1, "-": 1, "*": 2, "/": 2, "**": 3}
_TIME_ORDER = ("d", "h", "min", "s")
SUBJECT = ("subj", 0)  # the value a case statement tests, in its case tags
# Deepest nesting of blocks, parentheses and operators the parser takes: the parser, the
# checker and the interpreter walk the tree recursively, and a board's stack is small.
MAX_NESTING = 12


def _opens_constant(t, nt):
    """True when token ``t`` (``nt`` after it) starts a constant: '+ 2' does, '+ x' not."""
    if t[0] in (NUM, DIGITS, STR, ABST, RELT) or t[1] == "TRUE" or t[1] == "FALSE":
        return True
    return t[0] == OP and (t[1] == "+" or t[1] == "-") and nt[0] in (NUM, DIGITS, RELT)


def _numeric(v):
    t = type(v)
    return t is int or t is float or isinstance(v, units.Quantity)


def _show(tok):
    if tok[0] == EOF:
        return "end of text"
    if tok[0] == STR:
        return 'string "%s"' % tok[1]
    return "'%s'" % (tok[1],)


class ExprParser:
    def __init__(self, tokens):
        self.toks = tokens
        self.i = 0
        self.depth = 0

    def enter(self):
        """One level deeper (a block, a parenthesis, an operator); refused past the limit."""
        self.depth += 1
        if self.depth > MAX_NESTING:
            self.err("nesting deeper than %d levels" % MAX_NESTING)

    # token helpers
    def tok(self, k=0):
        j = self.i + k
        return self.toks[j] if j < len(self.toks) else self.toks[-1]

    def pos(self):
        return self.toks[self.i][2]

    def err(self, msg, p=None):
        raise PlutoSyntaxError(msg, *line_col(self.pos() if p is None else p))

    def at(self, *words):
        for k, w in enumerate(words):
            t = self.tok(k)
            if t[1] != w or t[0] not in (WORD, OP):
                return False
        return True

    def take(self, *words):
        if self.at(*words):
            self.i += len(words)
            return True
        return False

    def expect(self, *words, after=""):
        if not self.take(*words):
            self.err(
                "expected '%s'%s, found %s"
                % (" ".join(words), " " + after if after else "", _show(self.tok()))
            )

    def isop(self, sym):
        t = self.toks[self.i]
        return t[0] == OP and t[1] == sym

    def name(self, what="a name", limit=99):
        """A multi-word identifier: the run of non-reserved words here; a word after the first
        may start with a digit ("Wheel 2", "Heater 2b")."""
        words = []
        end = -1  # where the last word ends (line, column): "2" then "b" glued is one word
        start = self.i
        while self.i - start < limit:
            t = self.toks[self.i]
            k = t[0]
            if k == DIGITS and words:
                pass
            elif k != WORD or t[1] in RESERVED:
                break
            elif t[1] == "save" and self.tok(1)[1] == "context":  # a wait's save context
                break
            if words and t[2] == end:
                words[-1] += t[1]
            else:
                words.append(t[1])
            end = t[2] + len(t[1])
            self.i += 1
        if not words:
            self.err("expected %s, found %s" % (what, _show(self.tok())))
        return " ".join(words)

    def object_type(self):
        """The object type that starts here and is followed by a name, its words taken, or
        None."""
        t = self.toks[self.i]
        if t[0] != WORD or t[1] not in _TYPE_FIRST:
            return None
        for words in OBJECT_TYPES:
            if self.at(*words):
                nxt = self.tok(len(words))
                if nxt[0] == WORD and nxt[1] not in RESERVED:
                    self.i += len(words)
                    return " ".join(words)
        return None

    def object_type_here(self):
        save = self.i
        t = self.object_type()
        self.i = save
        return t is not None

    def ref(self, what="a reference"):
        """Object reference ``[type] name {of [type] name}`` as a mutable node the checker
        resolves: ['r', pos, names, object type of the first name, kind, target]. The types of
        the names after 'of' are read and not kept: the names alone say what they are."""
        p = self.pos()
        otype = self.object_type()
        names = [self.name(what)]
        while self.at("of"):
            self.i += 1
            self.object_type()
            names.append(self.name(what))
        return ["r", p, tuple(names), otype, None, None]

    # expressions: OR < XOR < AND < relational < + - < * / < ** < unary, left associative
    # but **. Precedence climbing keeps the Python calls per parenthesis to four (expr,
    # relational, _arith, _simple): each costs C stack on MicroPython, and a Pyboard has 15 KiB.
    def expr(self, min_prec=1, operand=None):
        """A logical expression over relations, or over ``operand()`` (a case tag's)."""
        left = operand() if operand else self.relational()
        while True:
            t = self.toks[self.i]
            prec = _LOGIC.get(t[1], 0) if t[0] == WORD else 0
            if prec < min_prec:
                return left
            self.i += 1
            left = ("l", t[2], t[1], left, self.expr(prec + 1, operand))

    def relational(self, subject=None):
        left = subject or self._arith(1)
        t = self.toks[self.i]
        p = t[2]
        if t[0] == OP and t[1] in RELOPS:
            self.i += 1
            return ("cmp", p, t[1], left, self._arith(1))
        if self.take("between"):
            lo = self.term()
            self.expect("and", after="in between")
            return ("btw", p, left, lo, self.term())
        if self.take("within"):
            tol = self.constant()
            pct = False
            if self.isop("%"):
                self.i += 1
                pct = True
            else:  # 'within 5 [mV] of': units may follow any constant; twice is a load error
                u = self.unit()
                if u is not None:
                    v = tol[2]
                    t = type(v)
                    tol = ("c", tol[1], units.Quantity(v, u)) if t is int or t is float else (
                        "c", tol[1], v, u)  # fmt: skip
            self.expect("of", after="in within")
            return ("wi", p, left, tol, pct, self.term())
        if self.at("in") and self.tok(1)[1] == "(":
            self.i += 2
            items = [self.term()]
            while self.isop(","):
                self.i += 1
                items.append(self.term())
            self.expect(")")
            return ("in", p, left, tuple(items))
        if subject is not None:
            self.err("expected a comparison in the case tag, found %s" % _show(self.tok()))
        return left

    def term(self):
        return self._arith(1)

    def _arith(self, min_prec):
        self.enter()  # simple(), inline: one Python call less per parenthesis
        try:
            left = self._simple()
        finally:
            self.depth -= 1
        while True:
            t = self.toks[self.i]
            prec = _ARITH.get(t[1], 0) if t[0] == OP else 0
            if prec < min_prec:
                return left
            self.i += 1
            if prec == 3:  # "**" binds to the right, one level deeper each
                self.enter()
                try:
                    right = self._arith(3)
                finally:
                    self.depth -= 1
            else:
                right = self._arith(prec + 1)
            left = ("b", t[2], t[1], left, right)

    def simple(self):
        self.enter()
        try:
            return self._simple()
        finally:
            self.depth -= 1

    def _simple(self):
        t = self.toks[self.i]
        k, v, p = t
        if k == NUM or k == DIGITS or k == RELT or k == ABST or k == STR:
            return self.constant()
        if k == OP:
            if v == "(":
                self.i += 1
                e = self.expr()
                self.expect(")", after="to close '('")
                return e
            if v == "+" or v == "-":
                self.i += 1
                x = self.simple()
                if x[0] == "c" and _numeric(x[2]):
                    return ("c", p, units.neg(x[2]) if v == "-" else x[2])
                return ("u", p, v, x)
        elif k == WORD:
            if v == "TRUE" or v == "FALSE":
                self.i += 1
                return ("c", p, v == "TRUE")
            if v == "NOT":
                self.i += 1
                return ("u", p, "NOT", self.simple())
            if self.take("ask", "user"):
                self.expect("(", after="after ask user")
                q = self.expr()
                dflt = self.expr() if self.take("default") else None
                self.expect(")", after="to close ask user")
                typ = self.typ() if self.take("expect") else None
                return ("ask", p, q, dflt, typ)
            f = self.function_name()
            if f is not None:
                return self.call(f, p)
            if self.take("confirmation", "status", "of"):  # 'confirmation' opens a body too
                r = self.ref()
                r[2] = ("confirmation status",) + r[2]
                return self.with_arguments(r)
            if v in _TYPE_FIRST and v in RESERVED:  # 'step X', 'event X', 'array X' ...
                save = self.i
                if self.object_type() is not None:
                    self.i = save
                    return self.with_arguments(self.ref())
            if v not in RESERVED:
                if v == "get" and self.tok(1)[0] == WORD and self.tok(1)[1] not in RESERVED:
                    self.i += 1
                save = self.i
                n = self.name()
                if self.isop("("):
                    return self.call(n, p)
                self.i = save
                return self.with_arguments(self.ref())
        self.err("expected an expression, found %s" % _show(t))

    def with_arguments(self, r):
        """An object property request may give arguments: ``<reference> with [<name> :=]
        <expression> {, ...} end with``; they are kept on the reference node (r[6])."""
        if not self.at("with") or self.tok(1)[1] in ("arguments", "value", "directives", "units"):
            return r
        self.i += 1
        args = [self.named_expr()]
        while self.isop(","):
            self.i += 1
            args.append(self.named_expr())
        self.expect("end", "with", after="after the arguments of %s" % " of ".join(r[2]))
        r.append(tuple(args))
        return r

    def named_expr(self):
        """``[<name> :=] <expression>``."""
        save = self.i
        if self.tok()[0] == WORD and self.tok()[1] not in RESERVED:
            n = self.name()
            if self.isop(":="):
                self.i += 1
                return (n, self.expr())
        self.i = save
        return (None, self.expr())

    def function_name(self):
        """The longest standard function name (Annex C, words such as 'to' or 'of' included)
        that starts here and is followed by '(', with its words taken; else None."""
        w = self.toks[self.i][1]
        if w not in FIRST_WORDS and w not in FUNCTIONS:  # 'log(' too: 'log' opens a statement
            return None
        words = []
        best = None
        for k in range(MAX_NAME_WORDS):
            t = self.tok(k)
            if t[0] != WORD:
                break
            words.append(t[1])
            nt = self.tok(k + 1)
            if nt[0] == OP and nt[1] == "(":
                name = " ".join(words)
                if name in FUNCTIONS or words[0] == "to":  # 'to ...(': a conversion, say so
                    best = (name, k + 1)
                break
        if best is None:
            return None
        self.i += best[1]
        return best[0]

    def call(self, fname, p):
        self.i += 1
        args = []
        if not self.isop(")"):
            args.append(self.expr())
            while self.isop(","):
                self.i += 1
                args.append(self.expr())
        self.expect(")", after="to close the arguments of %s" % fname)
        return ("f", p, fname, tuple(args))

    def constant(self):
        k, v, p = self.toks[self.i]
        self.i += 1
        if k == DIGITS:
            k, v = NUM, int(v)
        if k == STR:
            return ("c", p, v)
        if k == WORD and (v == "TRUE" or v == "FALSE"):
            return ("c", p, v == "TRUE")
        if k == ABST:
            return ("c", p, units.AbsTime(v))
        if k == RELT:
            return ("c", p, units.Quantity(v, "s"))
        if k == OP and v in "+-":
            c = self.constant()
            if not _numeric(c[2]):  # Annex A: a sign only before a number or a relative time
                self.err("a sign needs a number, found %s" % _show(self.toks[self.i - 1]), p)
            return ("c", p, units.neg(c[2]) if v == "-" else c[2])
        if k != NUM:
            self.i -= 1
            self.err("expected a constant, found %s" % _show(self.tok()))
        u = self.unit()
        if u is None:
            return ("c", p, v)
        if u in _TIME_ORDER:  # relative time chain such as "1 d 2 h" or "2min30s"
            total, last, fl = v * units.parse(u)[0], _TIME_ORDER.index(u), False
            while self.toks[self.i][0] in (DIGITS, NUM):
                nt = self.tok(1)
                if nt[0] != WORD or nt[1] not in _TIME_ORDER[last + 1 :]:
                    break
                n = self.toks[self.i][1]
                total += (int(n) if type(n) is str else n) * units.parse(nt[1])[0]
                last, fl = _TIME_ORDER.index(nt[1]), True
                self.i += 2
            if fl:
                return ("c", p, units.Quantity(total, "s"))
        return ("c", p, units.Quantity(v, u))

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
        return ("sys", p, n + " of " + self.type_path(True))

    def type_path(self, constant):
        """``<property> {of <property>} of (<reference> | [current] <kind> [of ...])``, with a
        constant after a property where ``constant``; as text."""
        parts = []
        while True:
            if self.take("current"):
                parts.append("current " + self.kind())
            else:
                k = self.kind(False)
                if k is None or self.tok()[0] == WORD and self.tok()[1] not in RESERVED:
                    t = self.object_type()
                    start = self.i
                    n = self.name("a property or an object")
                    nt = self.tok()
                    opens = _opens_constant(nt, self.tok(1))
                    if constant and nt[0] != EOF and nt[1] not in _TYPE_ENDS and not opens:
                        n = self.property_constant(start, n)
                    parts.append((t + " " if t else "") + n)
                else:
                    parts.append(k)
                t = self.tok()
                if constant and _opens_constant(t, self.tok(1)):
                    parts[-1] += " " + str(self.constant()[2])
            if not self.take("of"):
                return " of ".join(parts)

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
