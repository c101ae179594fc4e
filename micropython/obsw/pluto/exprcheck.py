"""PLUTO load-time typing of expressions (the checker's base class).

Types are (base, dims): base b Boolean, i integer, r real, s string, a absolute time,
e enumerated, ? unknown (a system value the resolver cannot type); dims is the unit's
dimension vector (numbers) or None. A relative time is ("r", TIME).
"""

from obsw.pluto import units
from obsw.pluto.builtins import spec
from obsw.pluto.lexer import PlutoError, line_col
from obsw.pluto.show import source, unit_text

NONE = units.NONE
TIME = units.TIME
ANY = ("?", None)
BOOL = ("b", None)
STRING = ("s", None)
ABS = ("a", None)
RELT = ("r", TIME)


class PlutoReferenceError(PlutoError):
    kind = "unknown_reference"


class PlutoTypeError(PlutoError):
    kind = "type_error"


def type_of_code(code, unit=None):
    """Checker type of a declared type code ('b', 'i', 'u', 'r', 's', 'a', 'rt', '?')."""
    if code == "rt":
        return RELT
    if code in ("i", "u", "r"):
        return ("r" if code == "r" else "i", units.dims(unit) if unit else NONE)
    if code in ("b", "s", "a"):
        return (code, None)
    return ANY


def type_of_value(v):
    if type(v) is bool:
        return BOOL
    if isinstance(v, int):
        return ("i", NONE)
    if isinstance(v, float):
        return ("r", NONE)
    if isinstance(v, str):
        return STRING
    if isinstance(v, units.Quantity):
        return ("i" if isinstance(v.value, int) else "r", units.dims(v.unit))
    if isinstance(v, units.AbsTime):
        return ABS
    return ANY


def _show(t):
    b, d = t
    if b in "ir":
        name = "integer" if b == "i" else "real"
        if d == TIME:
            return "relative time"
        return name if d == NONE or d is None else name + " with units"
    return {"b": "Boolean", "s": "string", "a": "absolute time", "e": "enumerated", "?": "?"}[b]


_KINDS = (
    ("N", "a number"),
    ("D", "a dimensionless number or an angle"),
    ("I", "an integer without units"),
    ("S", "a string"),
    ("A", "an absolute time"),
    ("R", "a relative time"),
)


def _kind(k):
    for key, text in _KINDS:
        if key == k:
            return text
    return k


def _num(t):
    return t[0] in "ir?"


class ExprChecker:
    def fail(self, cls, msg, p):
        self.errors.append(cls(msg, *line_col(p)))

    # scopes: list of dicts, innermost last; entries ("v", key) ("ev", name) ("enum", values)
    def want_bool(self, e, scopes, what):
        t = self.expr(e, scopes)
        if t[0] not in "b?":
            self.fail(PlutoTypeError, "%s must be Boolean, found %s" % (what, _show(t)), e[1])

    def want_rel(self, e, scopes, what):
        t = self.expr(e, scopes)
        if not (t[0] in "ir" and t[1] == TIME or t[0] == "?"):
            self.fail(
                PlutoTypeError, "%s must be a relative time (10 s), found %s" % (what, _show(t)),
                e[1])  # fmt: skip

    def expr(self, e, scopes):
        k = e[0]
        if k == "c":
            return type_of_value(e[2])
        if k == "r":
            return self.ref(e, scopes)
        if k == "subj":
            return self.subj[-1] if self.subj else ANY
        if k == "b":
            return self.arith(e, self.expr(e[3], scopes), self.expr(e[4], scopes))
        if k == "l":
            self.want_bool(e[3], scopes, "the operand of " + e[2])
            self.want_bool(e[4], scopes, "the operand of " + e[2])
            return BOOL
        if k == "u":
            t = self.expr(e[3], scopes)
            if e[2] == "NOT":
                if t[0] not in "b?":
                    self.fail(PlutoTypeError, "NOT needs a Boolean, found %s" % _show(t), e[1])
                return BOOL
            if not _num(t):
                self.fail(PlutoTypeError, "sign needs a number, found %s" % _show(t), e[1])
            return t
        if k == "cmp":
            self.comparable(e, self.expr(e[3], scopes), self.expr(e[4], scopes), e[2])
            return BOOL
        if k == "btw":
            t = self.expr(e[2], scopes)
            lo, hi = self.expr(e[3], scopes), self.expr(e[4], scopes)
            n = len(self.errors)  # one error per relation (the first bound that does not fit)
            self.comparable(e, t, lo, "<", e[2], e[3])
            if len(self.errors) == n:
                self.comparable(e, t, hi, "<", e[2], e[4])
            return BOOL
        if k == "wi":
            t = self.expr(e[2], scopes)
            tol = type_of_value(e[3][2])
            self.comparable(e, t, self.expr(e[5], scopes), "<", e[2], e[5])
            if len(e[3]) > 3 or not _num(tol):
                self.fail(PlutoTypeError, "within needs a number as its tolerance, with units"
                          " at most once: found %s" % source(e[3]), e[3][1])  # fmt: skip
            elif (
                not _num(t)
                or (e[4] and tol[1] != NONE)
                or (not e[4] and tol[1] != NONE and t[0] != "?" and tol[1] != t[1])
            ):
                self.fail(PlutoTypeError, "within needs numbers with matching units: %s within %s"
                          % (self.operand(e[2], t), source(e[3])), e[1])  # fmt: skip
            return BOOL
        if k == "in":
            t = self.expr(e[2], scopes)
            n = len(self.errors)
            for x in e[3]:
                tx = self.expr(x, scopes)
                if len(self.errors) == n:
                    self.comparable(e, t, tx, "=", e[2], x)
            return BOOL
        if k == "f":
            return self.function(e, [self.expr(a, scopes) for a in e[3]])
        if k == "ask":
            self.expr(e[2], scopes)
            if e[3] is not None:
                self.expr(e[3], scopes)
            t = e[4]
            if isinstance(t, tuple):
                return ANY if t[0] == "sys" else ("e", None)
            return type_of_code(t or "s")
        if k == "act":  # an activity handed as an argument: its name (and arguments)
            self.activity(e[2], scopes)
            return ANY
        if k == "refarg":  # an event or a system element handed as an argument: its name
            r = e[2]
            if e[3] == "event":
                self.event_ref(r, scopes)
            else:
                r[4], r[5] = "ctx", " of ".join(self._ctx_names(r[2]))
            return STRING
        return ANY

    def unit_name(self, e, t):
        """The unit an operand is written in: a constant's or a declaration's, else SI."""
        if e[0] == "c" and isinstance(e[2], units.Quantity):
            return e[2].unit
        if e[0] == "r":
            if e[4] == "v":
                return self.var_types[e[5]][1] or ""
            if e[4] == "p":
                return e[5][1] or ""
        return unit_text(t[1]) if t[1] else ""

    def operand(self, e, t):
        """An operand as messages name it: "3 m", "speed of Wheel (deg/s)", "mode (string)"."""
        if e[0] == "c":
            return source(e)
        u = self.unit_name(e, t)
        return "%s (%s)" % (source(e), u if u and t[0] in "ir" else _show(t))

    def comparable(self, e, a, b, op, x=None, y=None):
        if a[0] == "?" or b[0] == "?":
            return
        x = e[3] if x is None else x
        y = e[4] if y is None else y
        if _num(a) and _num(b):
            if a[1] == b[1]:
                return
            if a[1] == NONE or b[1] == NONE:
                # a number without units is dimensionless (Annex A: units are part of a
                # constant): '< 1800' against degC would silently mean 1800 degC
                ua = "none" if a[1] == NONE else self.unit_name(x, a)
                ub = "none" if b[1] == NONE else self.unit_name(y, b)
                self.fail(PlutoTypeError, "cannot compare %s with %s: units %s and %s differ (a"
                          " number without units is dimensionless)" % (self.operand(x, a),
                          self.operand(y, b), ua, ub), e[1])  # fmt: skip
                return
            self.fail(PlutoTypeError, "cannot compare %s with %s: units %s and %s differ"
                      % (self.operand(x, a), self.operand(y, b), self.unit_name(x, a),
                         self.unit_name(y, b)), e[1])  # fmt: skip
            return
        if a[0] in "se" and b[0] in "se":
            return
        if a[0] == b[0] and (a[0] != "b" or op in ("=", "!=")):
            return
        self.fail(PlutoTypeError, "cannot compare %s with %s: types %s and %s differ"
                  % (self.operand(x, a), self.operand(y, b), _show(a), _show(b)),
                  e[1])  # fmt: skip

    def arith(self, e, a, b):
        op, p = e[2], e[1]
        if a[0] == "?" or b[0] == "?":
            return a if b[0] == "?" else b
        if a[0] == "a" or b[0] == "a":
            if op == "-" and a == ABS and b == ABS:
                return RELT
            if op in "+-" and a == ABS and b[0] in "ir" and b[1] == TIME:
                return ABS
            if op == "+" and b == ABS and a[0] in "ir" and a[1] == TIME:
                return ABS
            self.fail(PlutoTypeError, "cannot apply %s to %s and %s"
                      % (op, self.operand(e[3], a), self.operand(e[4], b)), p)  # fmt: skip
            return ANY
        if not (_num(a) and _num(b)):
            self.fail(PlutoTypeError, "cannot apply %s to %s and %s"
                      % (op, self.operand(e[3], a), self.operand(e[4], b)), p)  # fmt: skip
            return ANY
        base = "i" if a[0] == "i" and b[0] == "i" and op != "/" else "r"
        if op in "+-":
            if a[1] != b[1]:
                x, y = e[3], e[4]
                self.fail(PlutoTypeError, "cannot %s %s and %s: units %s and %s differ"
                          % ("add" if op == "+" else "subtract", self.operand(x, a),
                             self.operand(y, b), self.unit_name(x, a) or "none",
                             self.unit_name(y, b) or "none"), p)  # fmt: skip
            return (base, a[1])
        if op == "**":
            if b[1] != NONE:
                self.fail(PlutoTypeError, "an exponent cannot have units", p)
            if a[1] != NONE:
                x = e[4]
                if x[0] != "c" or type(x[2]) is not int:
                    self.fail(PlutoTypeError, "units need a constant integer power", p)
                    return ANY
                return ("r", tuple(d * x[2] for d in a[1]))
            return (base, NONE)
        k = 1 if op == "*" else -1
        return (base, tuple(a[1][i] + k * b[1][i] for i in range(8)))

    def function(self, e, ts):
        f = spec(e[2])
        if f is None:
            self.fail(PlutoReferenceError, "unknown function %s" % e[2], e[1])
            return ANY
        lo, hi, kinds, res = f
        if len(ts) < lo or (hi >= 0 and len(ts) > hi):
            self.fail(PlutoTypeError, "%s takes %s arguments, got %d"
                      % (e[2], lo if lo == hi else "%d or more" % lo, len(ts)), e[1])  # fmt: skip
            return ANY
        for i, t in enumerate(ts):
            kind = kinds[min(i, len(kinds) - 1)] if kinds else "*"
            if t[0] == "?" or kind == "*":
                continue
            ok = (
                (kind == "N" and _num(t))
                or (kind == "D" and _num(t) and t[1] == NONE)
                or (kind == "I" and t[0] == "i" and t[1] == NONE)
                or (kind == "S" and t[0] in "se")
                or (kind == "A" and t[0] == "a")
                or (kind == "R" and _num(t) and t[1] == TIME)
            )
            if not ok:
                self.fail(PlutoTypeError, "argument %d of %s, %s, is not %s"
                          % (i + 1, e[2], self.operand(e[3][i], t), _kind(kind)),
                          e[1])  # fmt: skip
        first = ts[0] if ts else ANY
        if res == "=":
            return first
        if res == "i=":
            return ("i", first[1] if first[0] != "?" else NONE)
        if res == "sqrt":
            if first[0] == "?" or first[1] is None:
                return ("r", NONE) if first[0] != "?" else ANY
            for d in first[1]:
                if d % 2:
                    self.fail(PlutoTypeError, "sqrt of %s: its unit %s is not a square"
                              % (self.operand(e[3][0], first), self.unit_name(e[3][0], first)),
                              e[1])  # fmt: skip
                    return ANY
            return ("r", tuple([d // 2 for d in first[1]]))
        return type_of_code(res)


_DECLARED = {
    "b": "Boolean",
    "i": "signed integer",
    "u": "unsigned integer",
    "r": "real",
    "s": "string",
    "a": "absolute time",
    "rt": "relative time",
}


def _a(text):
    return ("an " if text[:1] in "aeiouAEIOU" else "a ") + text
