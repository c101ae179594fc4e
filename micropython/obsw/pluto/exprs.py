"""PLUTO expression parser: token helpers, names, references, constants with units, operators."""

from obsw.pluto import units
from obsw.pluto.builtins import FIRST_WORDS, FUNCTIONS, MAX_NAME_WORDS
from obsw.pluto.lexer import ABST, EOF, NUM, OP, RELT, STR, WORD, PlutoSyntaxError, line_col

# Words that end a multi-word name: every keyword that may follow a name or open a statement.
RESERVED = set(
    (
        "of with end then do to by is and or timeout raise refer default expect described"
        " until else otherwise in initiate if while for repeat wait log inform main watchdog"
        " confirmation preconditions declare step procedure event variable enumerated between"
        " within ask record array AND OR XOR NOT TRUE FALSE"
    ).split()
)
OBJECT_TYPES = ("variable", "parameter", "argument", "activity", "event", "step")
RELOPS = ("=", "!=", "<", ">", "<=", ">=")
_LOGIC = {"OR": 1, "XOR": 2, "AND": 3}
_ARITH = {"+": 1, "-": 1, "*": 2, "/": 2, "**": 3}
_TIME_ORDER = ("d", "h", "min", "s")
SUBJECT = ("subj", 0)  # the value a case statement tests, in its case tags
# Deepest nesting of blocks, parentheses and operators the parser takes: the parser, the
# checker and the interpreter walk the tree recursively, and a board's stack is small.
MAX_NESTING = 12


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

    def name(self, what="a name"):
        """A multi-word identifier: the run of non-reserved words here."""
        words = []
        while True:
            t = self.toks[self.i]
            if t[0] != WORD or t[1] in RESERVED:
                break
            words.append(t[1])
            self.i += 1
        if not words:
            self.err("expected %s, found %s" % (what, _show(self.tok())))
        return " ".join(words)

    def ref(self, what="a reference"):
        """Object reference ``[type] name {of name}`` as a mutable node the checker resolves:
        ['r', pos, names, object type, kind, target]."""
        p = self.pos()
        otype = None
        t = self.tok()
        if t[0] == WORD and t[1] in OBJECT_TYPES and self.tok(1)[0] == WORD:
            nxt = self.tok(1)[1]
            if nxt not in RESERVED or nxt == "event":
                otype = t[1]
                self.i += 1
        names = [self.name(what)]
        while self.at("of"):
            self.i += 1
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
        if k == NUM or k == RELT or k == ABST or k == STR:
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
                if x[0] == "c" and type(x[2]) is not bool and not isinstance(x[2], str):
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
                return r
            if v not in RESERVED:
                if v == "get" and self.tok(1)[0] == WORD and self.tok(1)[1] not in RESERVED:
                    self.i += 1
                save = self.i
                n = self.name()
                if self.isop("("):
                    return self.call(n, p)
                self.i = save
                return self.ref()
        self.err("expected an expression, found %s" % _show(t))

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
        if k == STR:
            return ("c", p, v)
        if k == ABST:
            return ("c", p, units.AbsTime(v))
        if k == RELT:
            return ("c", p, units.Quantity(v, "s"))
        if k == OP and v in "+-":
            c = self.constant()
            return ("c", p, units.neg(c[2]) if v == "-" else c[2])
        if k != NUM:
            self.i -= 1
            self.err("expected a constant, found %s" % _show(self.tok()))
        u = self.unit()
        if u is None:
            return ("c", p, v)
        if u in _TIME_ORDER:  # relative time chain such as "1 d 2 h" or "2min30s"
            total, last, fl = v * units.parse(u)[0], _TIME_ORDER.index(u), False
            while self.toks[self.i][0] == NUM:
                nt = self.tok(1)
                if nt[0] != WORD or nt[1] not in _TIME_ORDER[last + 1 :]:
                    break
                total += self.toks[self.i][1] * units.parse(nt[1])[0]
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
        elif t[0] == WORD and t[1] not in RESERVED and units.symbol(t[1]):
            text = t[1]
            self.i += 1
            while True:
                t = self.toks[self.i]
                nt = self.tok(1)
                if t[0] == OP and t[1] == "^":
                    j = self.i + 1
                    sign = ""
                    if self.toks[j][1] == "-":
                        sign, j = "-", j + 1
                    if self.toks[j][0] != NUM:
                        self.err("expected an exponent after '^'")
                    text += "^" + sign + str(self.toks[j][1])
                    self.i = j + 1
                elif t[0] == OP and t[1] in "./" and nt[0] == WORD and units.symbol(nt[1]):
                    text += t[1] + nt[1]
                    self.i += 2
                else:
                    break
        else:
            return None
        try:
            units.parse(text)
        except units.UnitError as e:
            self.err(str(e), t[2])
        return text

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
            if self.take(*words):
                return code
        return ("e", self.name("a type"))
