"""PLUTO load-time checks: resolves every reference and types every statement before a run."""

from obsw.pluto.exprcheck import (
    _DECLARED,
    ANY,
    NONE,
    STRING,
    ExprChecker,
    PlutoReferenceError,
    PlutoTypeError,
    _a,
    _num,
    _show,
    type_of_code,
    type_of_value,
)
from obsw.pluto.signatures import SignatureChecker


class Checker(ExprChecker, SignatureChecker):
    """Resolves references in place (ref nodes get kind and target) and collects errors."""

    def __init__(self, resolver=None, arguments=None):
        self.resolver = resolver
        self.args = arguments or {}
        self.errors = []
        self.n = 0
        self.ctx = []
        self.subj = []
        self.var_types = {}  # variable key -> (type, unit, enumerated values or None, code)
        self.def_vars = {}  # id(definition node) -> keys of the variables it declares
        self.defs = []  # definitions being checked, innermost last
        self.saved = set()  # keys of values a save context statement holds (read only)

    def lookup(self, scopes, name, kinds):
        for s in reversed(scopes):
            e = s.get(name)
            if e and e[0] in kinds:
                return e
        return None

    def definition(self, node, scopes, is_proc=False):
        _, p, decls, pre, main, wd, conf = node
        scope = {}
        scopes = scopes + [scope]
        self.defs.append(id(node))
        for d in decls:
            if d[2] in scope:
                self.fail(PlutoTypeError, "%s declared twice" % d[2], d[1])
            if d[0] == "event":
                scope[d[2]] = ("ev", d[2])
            elif d[0] == "enum":
                scope[d[2]] = ("enum", d[3])
            else:
                self.n += 1
                key = "%d.%s" % (self.n, d[2])
                t, unit, vals = d[3], d[4], None
                if isinstance(t, tuple) and t[0] == "sys":  # a system property's values:
                    typ = ANY  # known to the system only, checked when the procedure runs
                elif isinstance(t, tuple):
                    e = self.lookup(scopes, t[1], ("enum",))
                    if e is None:
                        self.fail(PlutoReferenceError, "unknown type %s" % t[1], d[1])
                    vals = e and e[1]
                    typ = ("e", None)
                else:
                    typ = type_of_code(t, unit)
                    if unit and t not in ("i", "u", "r"):
                        self.fail(PlutoTypeError, "units on a non-numeric variable", d[1])
                    if t == "rt":
                        unit = "s"
                self.var_types[key] = (typ, unit, vals, t)
                self.def_vars.setdefault(id(node), []).append(key)
                scope[d[2]] = ("v", key)
        for c in pre or ():
            self.condition(c, scopes)
        self.block(main, scopes, not is_proc)
        for s in wd or ():
            self.stmt(s, scopes)
        for c in conf or ():
            self.condition(c, scopes)
        self.defs.pop()

    def condition(self, c, scopes):
        if c[0] == "if":
            self.want_bool(c[2], scopes, "the condition")
        else:
            self.stmt(c, scopes)

    def block(self, stmts, scopes, step=True):
        for s in stmts:
            self.stmt(s, scopes)

    def timeout(self, to, scopes):
        if to:
            self.want_rel(to[0], scopes, "the timeout")
            if to[1]:
                self.event(to[1], scopes, to[2])

    def event(self, name, scopes, p):
        if not self.lookup(scopes, name, ("ev",)):
            self.fail(PlutoReferenceError, "unknown event %s (declare it)" % name, p)

    def stmt(self, s, scopes):
        k = s[0]
        if k == "set":
            vt = self.var(s[2], scopes)
            et = self.expr(s[3], scopes)
            if vt:
                self.assignable(vt, et, s[3], s[3][1], " ".join(s[2][2]))
        elif k == "if":
            self.want_bool(s[2], scopes, "the if condition")
            self.block(s[3], scopes)
            self.block(s[4], scopes)
        elif k == "case":
            st = self.expr(s[2], scopes)
            self.subj.append(st)
            for tag, body in s[3]:
                self.want_bool(tag, scopes, "the case tag")
                self.block(body, scopes)
            self.subj.pop()
            self.block(s[4] or (), scopes)
        elif k == "while":
            self.want_bool(s[2], scopes, "the while condition")
            self.timeout(s[3], scopes)
            self.block(s[4], scopes)
        elif k == "repeat":
            self.block(s[2], scopes)
            self.want_bool(s[3], scopes, "the until condition")
            self.timeout(s[4], scopes)
        elif k == "for":
            vt = self.var(s[2], scopes)
            for e in (s[3], s[4], s[5]):
                if e is not None:
                    t = self.expr(e, scopes)
                    if not _num(t):
                        self.fail(PlutoTypeError, "for bounds must be numbers", e[1])
                    elif vt:
                        self.assignable(vt, t, e, e[1], " ".join(s[2][2]))
            self.timeout(s[6], scopes)
            self.block(s[7], scopes)
        elif k == "wait":
            if s[2] == "until":
                t = self.expr(s[3], scopes)
                if t[0] not in "ba?":
                    self.fail(PlutoTypeError, "wait until needs a condition or an absolute time, "
                              "found %s" % _show(t), s[3][1])  # fmt: skip
            elif s[2] == "for":
                self.want_rel(s[3], scopes, "wait for")
            else:
                self.event_ref(s[3], scopes)
            if len(s) > 5 and s[5]:  # values saved when the wait ends
                self.save_context(("save", s[1], s[5]), scopes)
            self.timeout(s[4], scopes)
        elif k in ("init", "conf"):
            self.activity(s[2], scopes)
            if s[3]:
                scopes[-1][s[3]] = ("act", s[3])
            if k == "conf":
                self.continuation(s[4], scopes)
        elif k == "op":
            self.activity((s[2], s[3], ()), scopes)
        elif k == "step":
            scopes[-1][s[2]] = ("step", s[2])
            self.definition(s[3], scopes)
            self.continuation(s[4], scopes)
        elif k == "par":
            for b in s[3]:
                self.stmt(b, scopes)
        elif k in ("log", "inform"):
            for e in s[2]:
                self.expr(e, scopes)
        elif k == "save":
            self.save_context(s, scopes)
        elif k == "ctx":
            r = s[2]
            r[4], r[5] = "ctx", " of ".join(r[2])
            self.ctx.append(r[2])
            self.block(s[3], scopes)
            self.ctx.pop()

    def save_context(self, s, scopes):
        """Each saved value becomes a read-only variable of the enclosing step."""
        for item in s[2]:
            r, name = item[0], item[1]
            typ = self.ref(r, scopes)
            unit = r[5][1] if r[4] == "p" else None
            if r[4] == "v":
                unit = self.var_types[r[5]][1]
            if name in scopes[-1]:
                self.fail(PlutoTypeError, "%s declared twice" % name, s[1])
            self.n += 1
            key = "%d.%s" % (self.n, name)
            item[2] = key
            self.var_types[key] = (typ, unit, None, "saved")
            self.saved.add(key)
            self.def_vars.setdefault(self.defs[-1], []).append(key)
            scopes[-1][name] = ("v", key)

    def continuation(self, cont, scopes):
        for a in (cont or {}).values():
            if a[0] == "raise":
                self.event(a[2], scopes, a[1])
            elif a[0] == "restart":
                self.timeout(a[2], scopes)
                if a[3] is not None:
                    t = self.expr(a[3], scopes)
                    if t[0] not in "i?" or (t[0] == "i" and t[1] != NONE):
                        self.fail(PlutoTypeError, "max times needs an integer", a[3][1])
                if a[4]:
                    self.event(a[4], scopes, a[1])

    def activity(self, call, scopes):
        r = call[0]
        names = self._ctx_names(r[2])
        path = " of ".join(names)
        if self.resolver is not None:
            d = self.resolver.describe(path)
            if d is None or d[0] != "activity":
                self.fail(PlutoReferenceError, "unknown activity %s" % path, r[1])
        r[4], r[5] = "act", path
        for _, v in call[2]:
            self.argument(v, scopes)
        sig = None
        if self.resolver is not None and hasattr(self.resolver, "signature"):
            sig = self.resolver.signature(path)
        if sig is None or (call[1] and call[1][0][0] == "value set"):
            for _, v in call[1]:
                self.argument(v, scopes)
            return
        self.signature(path, sig, call[1], scopes, r[1])

    def argument(self, v, scopes):
        if isinstance(v, tuple) and v[0] in ("rec", "arr"):
            for _, x in v[2]:
                self.argument(x, scopes)
        else:
            self.expr(v, scopes)

    def _ctx_names(self, names):
        if self.ctx and len(names) == 1:
            return names + self.ctx[-1]
        return names

    def event_ref(self, r, scopes):
        names = r[2]
        if len(names) == 1 and self.lookup(scopes, names[0], ("ev",)):
            r[4], r[5] = "ev", names[0]
            return
        path = " of ".join(self._ctx_names(names))
        if self.resolver is not None:
            d = self.resolver.describe(path)
            if d is None or d[0] != "event":
                self.fail(PlutoReferenceError, "unknown event %s" % path, r[1])
        elif len(names) == 1 and not self.ctx:
            self.fail(PlutoReferenceError, "unknown event %s (declare it)" % path, r[1])
        r[4], r[5] = "ev", path

    def var(self, r, scopes):
        self.ref(r, scopes)
        if r[4] == "v" and r[5] in self.saved:
            self.fail(PlutoTypeError, "%s holds a saved context value, it cannot be assigned"
                      % " of ".join(r[2]), r[1])  # fmt: skip
            return None
        if r[4] != "v":
            if r[4] is not None:
                self.fail(PlutoTypeError, "only variables can be assigned, %s is not one"
                          % " of ".join(r[2]), r[1])  # fmt: skip
            return None
        return self.var_types[r[5]]

    def assignable(self, vinfo, et, e, p, name=None):
        vt, unit, vals, code = vinfo
        if et[0] == "?" or vt[0] == "?":
            return
        who = (name + ": ") if name else ""
        declared = _declared(code, vt)
        if vt[0] == "e":
            if et[0] != "s" and et[0] != "e":
                self.fail(PlutoTypeError, "%senumerated variable needs one of %s"
                          % (who, vals), p)  # fmt: skip
            elif e[0] == "c" and vals and e[2] not in vals:
                self.fail(PlutoTypeError, "%s%r is not one of %s"
                          % (who, e[2], ", ".join(vals)), p)  # fmt: skip
            return
        if vt[0] in "ir":
            if et[0] not in "ir":
                self.fail(PlutoTypeError, "%scannot assign %s to %s variable"
                          % (who, _a(_show(et)), _a(declared)), p)  # fmt: skip
            elif vt[0] == "i" and et[0] == "r":
                self.fail(PlutoTypeError, "%scannot assign a real to %s variable"
                          % (who, _a(declared)), p)  # fmt: skip
            elif et[1] != vt[1] and et[1] != NONE:
                self.fail(PlutoTypeError, "%scannot assign %s to %s variable with units %s: "
                          "units %s and %s differ" % (who, self.operand(e, et), _a(declared),
                          unit or "none", self.unit_name(e, et) or "none", unit or "none"),
                          p)  # fmt: skip
            return
        if vt[0] != et[0]:
            self.fail(PlutoTypeError, "%scannot assign %s to %s variable"
                      % (who, _a(_show(et)), _a(declared)), p)  # fmt: skip

    def ref(self, r, scopes):
        """Resolve a reference node in place and return its type."""
        t = self._ref(r, scopes)
        if len(r) > 6:  # an object property request's arguments: only the system's properties
            for _, e in r[6]:
                self.expr(e, scopes)
            if r[4] != "p":
                self.fail(PlutoTypeError, "%s takes no arguments: only a system object's"
                          " property may" % " of ".join(r[2]), r[1])  # fmt: skip
        return t

    def _ref(self, r, scopes):
        names = r[2]
        if names[0] == "value" and len(names) > 1:
            names = names[1:]
        if len(names) == 2 and names[0] in _STATUS_PROPERTIES:
            e = self.lookup(scopes, names[1], ("act", "step"))
            if e is not None:
                r[4], r[5] = "st", (names[0], names[1], e[0])
                return STRING
        if len(names) == 1:
            n = names[0]
            e = self.lookup(scopes, n, ("v", "act"))
            if e and r[3] in (None, "variable", "activity"):
                if e[0] == "v":
                    r[4], r[5] = "v", e[1]
                    return self.var_types[e[1]][0]
                r[4], r[5] = "s", n
                return STRING
            if n in self.args and r[3] in (None, "argument"):
                r[4], r[5] = "a", n
                return type_of_value(self.args[n])
            if not self.ctx:
                self.fail(PlutoReferenceError, "unknown reference %s" % n, r[1])
                return ANY
        path = " of ".join(self._ctx_names(names))
        typ, unit = ANY, None
        if self.resolver is not None:
            d = self.resolver.describe(path)
            if d is None or d[0] != "parameter":
                self.fail(PlutoReferenceError, "unknown parameter %s" % path, r[1])
            else:
                typ, unit = type_of_code(d[1], d[2]), d[2]
        r[4], r[5] = "p", (path, unit)
        return typ


def check(proc, resolver=None, arguments=None):
    """Resolve and type-check a parsed procedure in place; returns the variable table.

    Returns (variable types by key, variable keys by id of their definition node). Raises the
    first PlutoReferenceError or PlutoTypeError (by position); all errors are on the raised
    exception's ``errors`` attribute.
    """
    c = Checker(resolver, arguments)
    c.definition(proc, [], True)
    if c.errors:
        order = {}
        for i, x in enumerate(c.errors):  # MicroPython's sort is not stable: ties by order
            order[id(x)] = i
        c.errors.sort(key=lambda x: (x.line, x.col, order[id(x)]))
        err = c.errors[0]
        err.errors = c.errors
        raise err
    return c.var_types, c.def_vars


# properties of an activity statement (its refer by name) or a step, as strings
_STATUS_PROPERTIES = ("confirmation status", "execution status")


def _declared(code, vt):
    """The PLUTO type a variable was declared with, as written in the procedure."""
    if isinstance(code, tuple):
        return "enumerated " + str(code[1])
    return _DECLARED.get(code) or _show(vt)
