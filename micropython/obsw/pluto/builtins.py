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


def _round(x):
    return int(math.floor(x + 0.5)) if x >= 0 else -int(math.floor(-x + 0.5))


def _sign(x):
    return (x > 0) - (x < 0)


def _log10(x):
    f = getattr(math, "log10", None)  # exact for powers of ten; a port may lack it
    return f(x) if f else math.log(x) / math.log(10)


def _sqrt(x):
    """Square root; a quantity's unit must be a square (4 m^2 gives 2 m)."""
    if (x.value if isinstance(x, Quantity) else x) < 0:
        raise FunctionError("argument %s outside the function's domain" % text(x))
    if not isinstance(x, Quantity):
        return math.sqrt(x)
    d = dims(x.unit)
    for k in d:
        if k % 2:
            raise FunctionError("sqrt of %s: unit %s is not a square" % (text(x), x.unit))
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


def _atan2(y, x):
    return math.atan2(_num(y), _num(x))


def _trunc(x):
    return int(x)


def _floor(x):
    return int(math.floor(x))


def _ceiling(x):
    return int(math.ceil(x))


def _sign_of(x):
    return _sign(x.value if isinstance(x, Quantity) else x)


def _min(*xs):
    return _pick(xs, True)


def _max(*xs):
    return _pick(xs, False)


def _pick(xs, smallest):
    best = xs[0]
    for x in xs[1:]:
        a = best.value if isinstance(best, Quantity) else best
        b = x.to(best.unit).value if isinstance(x, Quantity) and isinstance(best, Quantity) else x
        if isinstance(b, Quantity):
            b = b.value
        if (b < a) if smallest else (b > a):
            best = x
    return best


def _concatenate(*s):
    return "".join(s)


def _upper(s):
    return s.upper()


def _lower(s):
    return s.lower()


# name: (function, "call min max kinds result"), the spec a constant string (no heap on a board)
#   call: m  maths on plain numbers (angles in radians, domain errors reported)
#         k  keeps the unit of its one argument (abs, round...)
#         -  called with the values as they are
#   min, max: argument counts (max * : any)
#   kinds: N number with any unit, D dimensionless number or angle, I integer, S string,
#          A absolute time, R relative time, * anything; the last kind repeats
#   result: = like the first argument, i= integer in the first argument's unit, sqrt, or a
#           type code (r, i, s, b, a, rt)
FUNCTIONS = {
    # mathematical
    "abs": (abs, "k 1 1 N ="),
    "sqrt": (_sqrt, "- 1 1 N sqrt"),
    "exp": (math.exp, "m 1 1 D r"),
    "ln": (math.log, "m 1 1 D r"),
    "log": (_log10, "m 1 1 D r"),
    "sin": (math.sin, "m 1 1 D r"),
    "cos": (math.cos, "m 1 1 D r"),
    "tan": (math.tan, "m 1 1 D r"),
    "arcsin": (math.asin, "m 1 1 D r"),
    "arccos": (math.acos, "m 1 1 D r"),
    "arctan": (math.atan, "m 1 1 D r"),
    "arctan2": (_atan2, "m 2 2 D r"),
    "sinh": (math.sinh, "m 1 1 D r"),
    "cosh": (math.cosh, "m 1 1 D r"),
    "tanh": (math.tanh, "m 1 1 D r"),
    "round": (_round, "k 1 1 N i="),
    "trunc": (_trunc, "k 1 1 N i="),
    "floor": (_floor, "k 1 1 N i="),
    "ceiling": (_ceiling, "k 1 1 N i="),
    "sign": (_sign_of, "- 1 1 N i"),
    "min": (_min, "- 1 * N ="),
    "max": (_max, "- 1 * N ="),
    # time
    "current time": (None, "- 0 0 - a"),
    "seconds": (seconds, "- 1 1 R r"),
    "to relative time": (_to_relative_time, "- 1 1 D rt"),
    "to absolute time": (_to_absolute_time, "- 1 1 S a"),
    "year": (_year, "- 1 1 A i"),
    "month": (_month, "- 1 1 A i"),
    "day of month": (_day_of_month, "- 1 1 A i"),
    "day of year": (_day_of_year, "- 1 1 A i"),
    "day of week": (_day_of_week, "- 1 1 A i"),
    "hour": (_hour, "- 1 1 A i"),
    "minute": (_minute, "- 1 1 A i"),
    "second": (_second, "- 1 1 A r"),
    # string
    "length": (len, "- 1 1 S i"),
    "substring": (_substring, "- 2 3 SII s"),
    "concatenate": (_concatenate, "- 1 * S s"),
    "index of": (_index_of, "- 2 2 S i"),
    "to upper case": (_upper, "- 1 1 S s"),
    "to lower case": (_lower, "- 1 1 S s"),
    "trim": (_strip, "- 1 1 S s"),
    "to string": (text, "- 1 1 * s"),
    "to integer": (_to_integer, "- 1 1 S i"),
    "to real": (_to_real, "- 1 1 S r"),
    "to Boolean": (_to_boolean, "- 1 1 S b"),
}

# the most words any function name has (the parser looks no further ahead), and the first
# words of the names of several words ("to": 'to <anything>(' is a conversion the checker names)
MAX_NAME_WORDS = 3
FIRST_WORDS = ("to", "current", "day", "index")


def spec(name):
    """(min args, max args or -1, argument kinds, result) of function ``name``, or None."""
    f = FUNCTIONS.get(name)
    if f is None:
        return None
    _, lo, hi, kinds, res = f[1].split(" ")
    return int(lo), -1 if hi == "*" else int(hi), kinds, res


def call(name, args, now):
    """Apply standard function ``name`` to evaluated ``args``; ``now`` feeds 'current time'."""
    if name == "current time":
        return AbsTime(now)
    f, how = FUNCTIONS[name]
    if how[0] == "k":
        x = args[0]
        return Quantity(f(x.value), x.unit) if isinstance(x, Quantity) else f(x)
    if how[0] == "m":
        try:
            return f(*[_num(x) for x in args])
        except (ValueError, ZeroDivisionError, OverflowError) as e:
            if isinstance(e, FunctionError):
                raise
            raise FunctionError(
                "argument %s outside the function's domain" % ", ".join([text(x) for x in args])
            ) from None
    return f(*args)
