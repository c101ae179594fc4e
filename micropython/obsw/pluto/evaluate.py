"""PLUTO expression evaluation and variable assignment (the interpreter's base class)."""

from obsw.pluto import builtins, show, units
from obsw.pluto.units import AbsTime, Quantity, compare


class PlutoRuntimeError(ValueError):
    """A failure while running (division by zero, a parameter that cannot be read...)."""

    def __init__(self, msg):
        super().__init__(msg)


_INT_MIN = -(1 << 63)
_INT_MAX = (1 << 64) - 1


def _bounded(v):
    """An integer result within PLUTO's 64-bit integers (signed or unsigned), else an error."""
    if type(v) is int and (v < _INT_MIN or v > _INT_MAX):
        raise PlutoRuntimeError("integer overflow: %d" % v)
    return v


class _Ask(Exception):
    """An ``ask user`` expression has no answer yet; the statement waits and re-evaluates."""

    def __init__(self, node):
        super().__init__("ask user")
        self.node = node


_NUMS = (int, float)


def _equal(a, b):
    if isinstance(a, (Quantity, AbsTime)) or isinstance(b, (Quantity, AbsTime)):
        return compare(a, b) == 0
    return a == b


def _cmp(op, a, b):
    ta, tb = type(a), type(b)
    if (ta is int or ta is float) and (tb is int or tb is float) or (ta is str and tb is str):
        if op == "<":
            return a < b
        if op == ">":
            return a > b
        if op == "<=":
            return a <= b
        if op == ">=":
            return a >= b
        return (a == b) == (op == "=")
    if op == "=":
        return _equal(a, b)
    if op == "!=":
        return not _equal(a, b)
    c = compare(a, b)
    if op == "<":
        return c < 0
    if op == ">":
        return c > 0
    if op == "<=":
        return c <= 0
    return c >= 0


_VERBS = {"+": "add", "-": "subtract", "*": "multiply", "/": "divide"}


def mismatch(verb, e, a, b, cause):
    """The run-time error for operands ``a`` and ``b`` of node ``e`` that do not go together:
    "cannot compare speed of Wheel (5 deg/s) with 3 m: units deg/s and m differ"."""
    x = show.operand(e[3], value=a)
    y = show.operand(e[4], value=b)
    ua, ub = show.unit_of_value(a), show.unit_of_value(b)
    why = ("units %s and %s differ" % (ua or "none", ub or "none")) if ua or ub else str(cause)
    link = " with " if verb == "compare" else " and "
    return PlutoRuntimeError("cannot %s %s%s%s: %s" % (verb, x, link, y, why))


def convert_answer(ans, code):
    """An operator's answer (text or value) as the type ``ask user ... expect`` names."""
    if not isinstance(ans, str) or code in (None, "s") or isinstance(code, tuple):
        return ans
    a = ans.strip()
    if code == "b":
        return a.lower() in ("true", "yes", "y", "1")
    if code in ("i", "u"):
        return int(a)
    if code == "r":
        return float(a)
    if code == "a":
        return AbsTime(units.parse_iso(a))
    if code == "rt":
        return Quantity(float(a), "s")
    return ans


class Evaluator:
    """Evaluates expression nodes against variables, arguments and the system."""

    def __init__(self, system, var_types, arguments):
        self.system = system
        self.vtypes = var_types
        self.args = arguments or {}
        self.vars = {}
        self.refer = {}  # activity statement name -> handle
        self.answers = {}  # id(ask node) -> converted answer
        self.subjects = []
        self.now = 0

    def eval(self, e):
        k = e[0]
        if k == "c":
            return e[2]
        if k == "r":
            return self.read(e)
        if k == "b":
            a = self.eval(e[3])
            b = self.eval(e[4])
            op = e[2]
            ta, tb = type(a), type(b)
            if (ta is int or ta is float) and (tb is int or tb is float):
                if op == "+":
                    return _bounded(a + b)
                if op == "-":
                    return _bounded(a - b)
                if op == "*":
                    return _bounded(a * b)
                if op == "/":
                    if b == 0:
                        raise PlutoRuntimeError("division by zero")
                    return a / b
                if a == 0 and b < 0:
                    raise PlutoRuntimeError("zero to a negative power")
                if ta is int and tb is int and b > 64 and (a > 1 or a < -1):
                    raise PlutoRuntimeError("integer overflow: %d ** %d" % (a, b))
                try:
                    return _bounded(a**b)
                except OverflowError:
                    raise PlutoRuntimeError("%r ** %r is out of range" % (a, b)) from None
            try:
                return units.arith(op, a, b)
            except ZeroDivisionError:
                raise PlutoRuntimeError("division by zero") from None
            except units.UnitError as x:
                raise mismatch(_VERBS.get(op, "apply " + op + " to"), e, a, b, x) from None
        if k == "cmp":
            a = self.eval(e[3])
            b = self.eval(e[4])
            try:
                return _cmp(e[2], a, b)
            except units.UnitError as x:
                raise mismatch("compare", e, a, b, x) from None
        if k == "l":
            a = self.eval(e[3])
            op = e[2]
            if op == "AND":
                return a and self.eval(e[4])
            if op == "OR":
                return a or self.eval(e[4])
            return a != self.eval(e[4])
        if k == "u":
            x = self.eval(e[3])
            if e[2] == "NOT":
                return not x
            return units.neg(x) if e[2] == "-" else x
        if k == "subj":
            return self.subjects[-1]
        if k == "btw":
            x = self.eval(e[2])
            return _cmp(">=", x, self.eval(e[3])) and _cmp("<=", x, self.eval(e[4]))
        if k == "wi":
            x = self.eval(e[2])
            ref = self.eval(e[5])
            tol = e[3][2]
            diff = units.arith("-", x, ref)
            if e[4]:
                lim = abs(ref.value if isinstance(ref, Quantity) else ref) * tol / 100
                return _cmp("<=", abs(diff.value if isinstance(diff, Quantity) else diff), lim)
            if isinstance(diff, Quantity):
                diff = Quantity(abs(diff.value), diff.unit)
                return _cmp("<=", diff, tol)
            return _cmp("<=", abs(diff), tol)
        if k == "in":
            x = self.eval(e[2])
            for item in e[3]:
                if _equal(x, self.eval(item)):
                    return True
            return False
        if k == "f":
            args = [self.eval(a) for a in e[3]]
            try:
                return builtins.call(e[2], args, self.now)
            except (ValueError, TypeError, ZeroDivisionError) as x:
                raise PlutoRuntimeError("%s: %s" % (e[2], x)) from None
        if k == "ask":
            key = id(e)
            if key in self.answers:
                return self.answers.pop(key)
            raise _Ask(e)
        raise PlutoRuntimeError("cannot evaluate %r" % (k,))

    def read(self, r):
        kind = r[4]
        if kind == "v":
            v = self.vars.get(r[5])
            if v is None:
                raise PlutoRuntimeError("variable %s used before it was assigned" % r[2][-1])
            return v
        if kind == "p":
            path, unit = r[5]
            try:
                if len(r) > 6:
                    args = {}
                    for i, (n, e) in enumerate(r[6]):
                        args[n or "arg%d" % (i + 1)] = self.eval(e)
                    v = self.system.request(path, args)
                else:
                    v = self.system.get(path)
            except (KeyError, ValueError, OSError) as x:
                raise PlutoRuntimeError("cannot read %s: %s" % (path, x)) from None
            if unit and type(v) in _NUMS:
                return Quantity(v, unit)
            return v
        if kind == "a":
            return self.args[r[5]]
        if kind == "st":
            return self.status_property(*r[5])
        if kind == "s":
            h = self.refer.get(r[5])
            if h is None:
                return "not initiated"
            return self.system.status(h) or "executing"
        raise PlutoRuntimeError("unresolved reference %s (procedure not checked)" % r[2][0])

    def status_property(self, prop, name, what):
        """``confirmation status`` (confirmed, not confirmed, aborted; "not available" before
        the end) or ``execution status`` (not initiated, executing, completed) of an activity
        statement's refer by name or of a step."""
        if what == "act":
            h = self.refer.get(name)
            st = None if h is None else self.system.status(h)
            started = h is not None
        else:
            st = getattr(self, "step_status", {}).get(name)
            started = st is not None
            if st == "executing":
                st = None
        if prop == "execution status":
            return "completed" if st else "executing" if started else "not initiated"
        return st or "not available"

    def assign(self, r, v):
        key = r[5]
        typ, unit, vals, code = self.vtypes[key]
        if unit:
            try:
                v = v.to(unit) if isinstance(v, Quantity) else Quantity(v, unit)
            except units.UnitError as x:
                raise PlutoRuntimeError(str(x)) from None
        if code in ("i", "u"):
            n = v.value if isinstance(v, Quantity) else v
            if type(n) is float:
                if n != int(n):
                    raise PlutoRuntimeError("%s is an integer, cannot hold %s" % (r[2][-1], n))
                n = int(n)
            if code == "u" and n < 0:
                raise PlutoRuntimeError("%s is unsigned, cannot hold %d" % (r[2][-1], n))
            v = Quantity(n, unit) if unit else n
        elif code == "r":
            if type(v) is int:
                v = float(v)
            elif isinstance(v, Quantity) and type(v.value) is int:
                v = Quantity(float(v.value), v.unit)
        elif vals and v not in vals:
            raise PlutoRuntimeError("%r is not a value of %s" % (v, r[2][-1]))
        self.vars[key] = v
