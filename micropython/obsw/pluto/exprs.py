"""PLUTO expression parser: constants with units, operators by precedence, function calls,
object property requests; names and references come from ``obsw.pluto.syntax``, units and
types from ``obsw.pluto.unitsyntax``."""

from obsw.pluto import units
from obsw.pluto.builtins import FIRST_WORDS, FUNCTIONS, MAX_NAME_WORDS
from obsw.pluto.lexer import ABST, DIGITS, NUM, OP, RELT, STR, WORD
from obsw.pluto.syntax import _TYPE_FIRST, RESERVED, _show
from obsw.pluto.unitsyntax import UnitTypeParser

RELOPS = ("=", "!=", "<", ">", "<=", ">=")
_LOGIC = {"OR": 1, "XOR": 2, "AND": 3}
_ARITH = {"+": 1, "-": 1, "*": 2, "/": 2, "**": 3}
_TIME_ORDER = ("d", "h", "min", "s")
SUBJECT = ("subj", 0)  # the value a case statement tests, in its case tags


def _numeric(v):
    t = type(v)
    return t is int or t is float or isinstance(v, units.Quantity)


class ExprParser(UnitTypeParser):
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
            if len(items) < 2:  # Annex A: 'in (' <term> {',' <term>}- ')'
                self.err("in (...) needs two values at least, found %s" % _show(self.tok()))
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
