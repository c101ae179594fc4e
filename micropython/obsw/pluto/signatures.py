"""PLUTO load-time checks of activity calls against their declared signatures (argument
names, types and units from the spacecraft database or a simulated system's description)."""

from obsw.errors import closest
from obsw.pluto.exprcheck import (
    _DECLARED,
    NONE,
    TIME,
    PlutoReferenceError,
    PlutoTypeError,
    _a,
    _show,
)
from obsw.pluto.system import norm
from obsw.pluto.units import Quantity, dims


class SignatureChecker:
    """Mixed into the checker: ``fail``, ``expr``, ``argument``, ``operand`` and ``unit_name``
    come from it."""

    def signature(self, path, sig, args, scopes, p):
        """Arguments against the activity's declared signature: names, count, types, units."""
        takes = ", ".join([a[0] for a in sig]) or "none"
        given = {}
        unknown = []  # (name, value, position) of arguments the activity does not declare
        for i, (name, v) in enumerate(args):
            q = v[1] if isinstance(v, tuple) else p
            if name is None:
                if i >= len(sig):
                    self.fail(PlutoTypeError, "activity %s takes %d arguments (%s), got %d"
                              % (path, len(sig), takes, len(args)), q)  # fmt: skip
                    self.argument(v, scopes)
                    continue
                decl = sig[i]
            else:
                decl = None
                for d in sig:
                    if norm(d[0]) == norm(name):
                        decl = d
                if decl is None:
                    unknown.append((name, q))
                    self.argument(v, scopes)
                    continue
            if decl[0] in given:
                self.fail(PlutoTypeError, "activity %s: argument %s given twice"
                          % (path, decl[0]), q)  # fmt: skip
            given[decl[0]] = True
            if v[0] in ("rec", "arr"):
                self.argument(v, scopes)
                if decl[1] != "?":
                    self.fail(PlutoTypeError, "activity %s: argument %s takes %s, got a%s"
                              % (path, decl[0], _a(_DECLARED[decl[1]]),
                                 " record" if v[0] == "rec" else "n array"), q)  # fmt: skip
                continue
            self.argument_type(path, decl, v, self.expr(v, scopes), q)
        for name, q in unknown:  # a misspelt name: say which declared one it resembles
            near = closest_argument(name, [d[0] for d in sig if d[0] not in given])
            hint = "; did you mean %s?" % near if near else ""
            if near:
                given[near] = True  # named by this error: not reported missing as well
            self.fail(PlutoReferenceError, "activity %s has no argument %s%s (takes: %s)"
                      % (path, name, hint, takes), q)  # fmt: skip
        at = unknown[0][1] if unknown else p  # after the misspelt names, that come first
        for d in sig:
            if d[0] not in given:
                self.fail(PlutoTypeError, "activity %s needs argument %s (takes: %s)"
                          % (path, d[0], takes), at)  # fmt: skip

    def argument_type(self, path, decl, v, et, p):
        name, code, unit = decl
        if type(code) is tuple:  # ("labels", {raw: label}): an enumerated argument
            return self.label_argument(path, name, code[1], v, et, p)
        if code == "?" or et[0] == "?":
            return
        want = _DECLARED[code] + (" in " + unit if unit and code != "rt" else "")
        why = None
        if code in ("i", "u", "r"):
            if et[0] not in "ir":
                why = "types %s and %s differ" % (_show(et), _DECLARED[code])
            elif code != "r" and et[0] == "r":
                why = "a real is no integer"
            elif et[1] != NONE and et[1] != (dims(unit) if unit else NONE):
                why = "units %s and %s differ" % (self.unit_name(v, et), unit or "none")
            elif code == "u" and v[0] == "c" and _below_zero(v[2]):
                why = "it is negative"
        elif code == "rt":
            if not (et[0] in "ir" and et[1] == TIME):
                why = "it is no relative time"
        elif code == "s":
            if et[0] not in "se":
                why = "types %s and string differ" % _show(et)
        elif et[0] != code:
            why = "types %s and %s differ" % (_show(et), _DECLARED[code])
        if why:
            self.fail(PlutoTypeError, "activity %s: argument %s takes %s, got %s: %s"
                      % (path, name, _a(want), self.operand(v, et), why), p)  # fmt: skip

    def label_argument(self, path, name, labels, v, et, p):
        """A label of the enumeration (a string constant checked at load time), a number of
        it, or a string the procedure computes (checked when it runs)."""
        known = list(labels.values())
        if v[0] == "c" and type(v[2]) is str:
            if v[2] in known:
                return
            near = closest(v[2], known)
            why = "no label %r%s" % (v[2], "; did you mean %r?" % near if near else "")
        elif v[0] == "c" and type(v[2]) is int:
            if v[2] in labels:
                return
            why = "no label numbered %d" % v[2]
        elif et[0] in "seiu?":
            return
        else:
            why = "types %s and label differ" % _show(et)
        self.fail(PlutoTypeError, "activity %s: argument %s takes one of %s, got %s: %s"
                  % (path, name, ", ".join(known), self.operand(v, et), why), p)  # fmt: skip


def closest_argument(name, names):
    """The one of ``names`` nearest to ``name`` when near enough to be a typo of it (at most a
    third differs, spaces, underscores and case aside), else None."""
    forms = {}
    for n in names:
        forms.setdefault(norm(n), n)
    near = closest(norm(name), list(forms))
    return None if near is None else forms[near]


def _below_zero(v):
    n = v.value if isinstance(v, Quantity) else v
    return type(n) is not bool and isinstance(n, (int, float)) and n < 0
