"""PLUTO built-in functions (mathematical, time and string functions, ECSS-E-ST-70-32C Annex C)."""

import math

from obsw.pluto.units import AbsTime, Quantity, UnitError, dims, seconds


class FunctionError(ValueError):
    def __init__(self, msg):
        super().__init__(msg)


def _num(x):
    # angles may carry units (deg, rad, arcmin): functions work in radians
    if isinstance(x, Quantity):
        if dims(x.unit) != (0, 0, 0, 0, 0, 0, 0, 0):
            raise UnitError("%s needs a dimensionless value, got %s" % ("function", x.unit))
        return x.si()
    return x


def _keep(f):
    # result keeps the unit of the argument (abs, round, floor...)
    def g(x):
        if isinstance(x, Quantity):
            return Quantity(f(x.value), x.unit)
        return f(x)

    return g


def _round(x):
    return int(math.floor(x + 0.5)) if x >= 0 else -int(math.floor(-x + 0.5))


def _sign(x):
    return (x > 0) - (x < 0)


def _minmax(pick):
    def f(*xs):
        best = xs[0]
        for x in xs[1:]:
            a = best.value if isinstance(best, Quantity) else best
            b = (
                x.to(best.unit).value
                if isinstance(x, Quantity) and isinstance(best, Quantity)
                else x
            )
            if isinstance(b, Quantity):
                b = b.value
            if pick(b, a):
                best = x
        return best

    return f


def _substring(s, start, length=None):
    if start < 1:
        raise FunctionError("substring start %d, must be 1 or more" % start)
    return s[start - 1 :] if length is None else s[start - 1 : start - 1 + length]


def _math1(f):
    def g(x):
        try:
            return f(_num(x))
        except (ValueError, ZeroDivisionError):
            raise FunctionError("argument %r outside the function's domain" % (x,)) from None

    return g


# name: (function, min args, max args (-1: any), argument kinds, result kind)
# kinds: N number with any unit, D dimensionless number or angle, S string, A absolute time,
#        R relative time; results: = (like the first argument), r, i, s, a, rt
FUNCTIONS = {
    "abs": (_keep(abs), 1, 1, "N", "="),
    "sqrt": (_math1(math.sqrt), 1, 1, "D", "r"),
    "exp": (_math1(math.exp), 1, 1, "D", "r"),
    "ln": (_math1(math.log), 1, 1, "D", "r"),
    "log": (_math1(lambda x: math.log(x) / math.log(10)), 1, 1, "D", "r"),
    "sin": (_math1(math.sin), 1, 1, "D", "r"),
    "cos": (_math1(math.cos), 1, 1, "D", "r"),
    "tan": (_math1(math.tan), 1, 1, "D", "r"),
    "arcsin": (_math1(math.asin), 1, 1, "D", "r"),
    "arccos": (_math1(math.acos), 1, 1, "D", "r"),
    "arctan": (_math1(math.atan), 1, 1, "D", "r"),
    "arctan2": (lambda y, x: math.atan2(_num(y), _num(x)), 2, 2, "D", "r"),
    "round": (_keep(_round), 1, 1, "N", "i="),
    "trunc": (_keep(lambda x: int(x)), 1, 1, "N", "i="),
    "floor": (_keep(lambda x: int(math.floor(x))), 1, 1, "N", "i="),
    "ceiling": (_keep(lambda x: int(math.ceil(x))), 1, 1, "N", "i="),
    "sign": (lambda x: _sign(x.value if isinstance(x, Quantity) else x), 1, 1, "N", "i"),
    "min": (_minmax(lambda b, a: b < a), 1, -1, "N", "="),
    "max": (_minmax(lambda b, a: b > a), 1, -1, "N", "="),
    "current time": (None, 0, 0, "", "a"),
    "seconds": (lambda r: seconds(r), 1, 1, "R", "r"),
    "length": (len, 1, 1, "S", "i"),
    "substring": (_substring, 2, 3, "SNN", "s"),
    "concatenate": (lambda *s: "".join(s), 1, -1, "S", "s"),
    "to string": (None, 1, 1, "*", "s"),
}


def call(name, args, now):
    """Apply built-in function ``name`` to evaluated ``args``; ``now`` feeds 'current time'."""
    if name == "current time":
        return AbsTime(now)
    if name == "to string":
        from obsw.pluto.units import text

        return text(args[0])
    return FUNCTIONS[name][0](*args)
