"""PLUTO standard functions (ECSS-E-ST-70-32C Annex C): mathematical, time and string ones.

A function's name may have several words (``to string``, ``day of year``): the parser takes the
longest name in ``FUNCTIONS`` that is followed by ``(``, whatever words it holds.
"""

import math

from obsw.pluto.show import unit_text
from obsw.pluto.units import (
    AbsTime,
    Quantity,
    UnitError,
    civil,
    days_from_civil,
    dims,
    parse_iso,
    seconds,
    text,
)


class FunctionError(ValueError):
    def __init__(self, msg):
        super().__init__(msg)


def _num(x):
    # angles may carry units (deg, rad, arcmin): functions work in radians
    if isinstance(x, Quantity):
        if dims(x.unit) != (0, 0, 0, 0, 0, 0, 0, 0):
            raise UnitError("the function needs a dimensionless value, got %s" % x.unit)
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


def _math1(f):
    def g(x):
        try:
            return f(_num(x))
        except (ValueError, ZeroDivisionError, OverflowError):
            raise FunctionError("argument %s outside the function's domain" % text(x)) from None

    return g


def _log10(x):
    f = getattr(math, "log10", None)  # exact for powers of ten; a port may lack it
    return f(x) if f else math.log(x) / math.log(10)


def _sqrt(x):
    """Square root; a quantity's unit must be a square (4 m^2 gives 2 m)."""
    if not isinstance(x, Quantity):
        return _math1(math.sqrt)(x)
    d = dims(x.unit)
    for k in d:
        if k % 2:
            raise FunctionError("sqrt of %s: unit %s is not a square" % (text(x), x.unit))
    if x.value < 0:
        raise FunctionError("argument %s outside the function's domain" % text(x))
    si = x.si()
    unit = unit_text(tuple(k // 2 for k in d))
    return Quantity(math.sqrt(si), unit) if unit else math.sqrt(si)


# -- time functions: absolute times are seconds since 1970-01-01T00:00:00Z (UTC)


def _fields(t):
    s = t.seconds
    whole = int(s // 1)
    days, rem = divmod(whole, 86400)
    return days, rem, s - whole


def _year(t):
    return civil(_fields(t)[0])[0]


def _month(t):
    return civil(_fields(t)[0])[1]


def _day_of_month(t):
    return civil(_fields(t)[0])[2]


def _day_of_year(t):
    days = _fields(t)[0]
    return days - days_from_civil(civil(days)[0], 1, 1) + 1


def _day_of_week(t):
    # ISO 8601: Monday is 1, Sunday is 7; 1970-01-01 was a Thursday
    return (_fields(t)[0] + 3) % 7 + 1


def _hour(t):
    return _fields(t)[1] // 3600


def _minute(t):
    return _fields(t)[1] // 60 % 60


def _second(t):
    _, rem, frac = _fields(t)
    s = rem % 60
    return s + frac if frac else s


def _to_absolute_time(s):
    try:
        return AbsTime(parse_iso(s.strip()))
    except UnitError:
        raise FunctionError("to absolute time: %r is no ISO 8601 time" % (s,)) from None


def _to_relative_time(x):
    return Quantity(x, "s")


# -- string functions (positions count from 1)


def _substring(s, start, length=None):
    if start < 1:
        raise FunctionError("substring start %d, must be 1 or more" % start)
    if length is not None and length < 0:
        raise FunctionError("substring length %d, must be 0 or more" % length)
    return s[start - 1 :] if length is None else s[start - 1 : start - 1 + length]


def _index_of(s, part):
    return s.find(part) + 1


def _strip(s):
    return s.strip()


def _to_integer(s):
    try:
        return int(s.strip(), 0) if s.strip()[:2] in ("0x", "0X") else int(s.strip())
    except ValueError:
        raise FunctionError("to integer: %r is no integer" % (s,)) from None


def _to_real(s):
    try:
        v = float(s.strip())
    except ValueError:
        raise FunctionError("to real: %r is no real number" % (s,)) from None
    if v - v != 0:
        raise FunctionError("to real: %r is not finite" % (s,))
    return v


def _to_boolean(s):
    t = s.strip().upper()
    if t == "TRUE":
        return True
    if t == "FALSE":
        return False
    raise FunctionError("to Boolean: %r is neither TRUE nor FALSE" % (s,))


# name: (function, min args, max args (-1: any), argument kinds, result kind)
# kinds: N number with any unit, D dimensionless number or angle, I integer, S string,
#        A absolute time, R relative time, * anything; the last kind repeats.
# results: = (like the first argument), i= (integer with the first argument's unit), and the
#        type codes r, i, s, b, a, rt
FUNCTIONS = {
    # mathematical
    "abs": (_keep(abs), 1, 1, "N", "="),
    "sqrt": (_sqrt, 1, 1, "N", "sqrt"),
    "exp": (_math1(math.exp), 1, 1, "D", "r"),
    "ln": (_math1(math.log), 1, 1, "D", "r"),
    "log": (_math1(_log10), 1, 1, "D", "r"),
    "sin": (_math1(math.sin), 1, 1, "D", "r"),
    "cos": (_math1(math.cos), 1, 1, "D", "r"),
    "tan": (_math1(math.tan), 1, 1, "D", "r"),
    "arcsin": (_math1(math.asin), 1, 1, "D", "r"),
    "arccos": (_math1(math.acos), 1, 1, "D", "r"),
    "arctan": (_math1(math.atan), 1, 1, "D", "r"),
    "arctan2": (lambda y, x: math.atan2(_num(y), _num(x)), 2, 2, "D", "r"),
    "sinh": (_math1(math.sinh), 1, 1, "D", "r"),
    "cosh": (_math1(math.cosh), 1, 1, "D", "r"),
    "tanh": (_math1(math.tanh), 1, 1, "D", "r"),
    "round": (_keep(_round), 1, 1, "N", "i="),
    "trunc": (_keep(lambda x: int(x)), 1, 1, "N", "i="),
    "floor": (_keep(lambda x: int(math.floor(x))), 1, 1, "N", "i="),
    "ceiling": (_keep(lambda x: int(math.ceil(x))), 1, 1, "N", "i="),
    "sign": (lambda x: _sign(x.value if isinstance(x, Quantity) else x), 1, 1, "N", "i"),
    "min": (_minmax(lambda b, a: b < a), 1, -1, "N", "="),
    "max": (_minmax(lambda b, a: b > a), 1, -1, "N", "="),
    # time
    "current time": (None, 0, 0, "", "a"),
    "seconds": (seconds, 1, 1, "R", "r"),
    "to relative time": (_to_relative_time, 1, 1, "D", "rt"),
    "to absolute time": (_to_absolute_time, 1, 1, "S", "a"),
    "year": (_year, 1, 1, "A", "i"),
    "month": (_month, 1, 1, "A", "i"),
    "day of month": (_day_of_month, 1, 1, "A", "i"),
    "day of year": (_day_of_year, 1, 1, "A", "i"),
    "day of week": (_day_of_week, 1, 1, "A", "i"),
    "hour": (_hour, 1, 1, "A", "i"),
    "minute": (_minute, 1, 1, "A", "i"),
    "second": (_second, 1, 1, "A", "r"),
    # string
    "length": (len, 1, 1, "S", "i"),
    "substring": (_substring, 2, 3, "SII", "s"),
    "concatenate": (lambda *s: "".join(s), 1, -1, "S", "s"),
    "index of": (_index_of, 2, 2, "S", "i"),
    "to upper case": (lambda s: s.upper(), 1, 1, "S", "s"),
    "to lower case": (lambda s: s.lower(), 1, 1, "S", "s"),
    "trim": (_strip, 1, 1, "S", "s"),
    "to string": (text, 1, 1, "*", "s"),
    "to integer": (_to_integer, 1, 1, "S", "i"),
    "to real": (_to_real, 1, 1, "S", "r"),
    "to Boolean": (_to_boolean, 1, 1, "S", "b"),
}

# the most words any function name has (the parser looks no further ahead), and the words
# function names start with ("to" too: 'to <anything>(' is a conversion the checker names)
MAX_NAME_WORDS = 3
FIRST_WORDS = set(["to"])
for _name in FUNCTIONS:
    FIRST_WORDS.add(_name.split(" ")[0])


def call(name, args, now):
    """Apply standard function ``name`` to evaluated ``args``; ``now`` feeds 'current time'."""
    if name == "current time":
        return AbsTime(now)
    return FUNCTIONS[name][0](*args)
