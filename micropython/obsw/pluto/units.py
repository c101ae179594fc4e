"""PLUTO values with engineering units (ECSS-E-ST-70-32C Annex B), absolute times, arithmetic."""

import math

# Dimension vector: metre, kilogram, second, ampere, kelvin, mole, candela, bit.
_N = 8
NONE = (0, 0, 0, 0, 0, 0, 0, 0)
TIME = (0, 0, 1, 0, 0, 0, 0, 0)


def isdigits(s):
    """True for a non-empty string of ASCII digits (str.isdigit also takes '²' on CPython)."""
    if not s:
        return False
    for c in s:
        if c < "0" or c > "9":
            return False
    return True


class UnitError(ValueError):
    """A unit text that is not Annex B, or an operation mixing incompatible dimensions."""

    def __init__(self, msg):
        super().__init__(msg)


def _d(m=0, kg=0, s=0, a=0, k=0, mol=0, cd=0, bit=0):
    return (m, kg, s, a, k, mol, cd, bit)


_PI = math.pi
# symbol: (scale to SI, dimensions, prefix class) -- class 1: any decimal prefix,
# 2: multiples only, 3: submultiples only, 4: binary or decimal multiples, 0: no prefix.
_UNITS = {
    "m": (1, _d(m=1), 1),
    "g": (0.001, _d(kg=1), 1),
    "s": (1, TIME, 1),
    "A": (1, _d(a=1), 1),
    "K": (1, _d(k=1), 1),
    "mol": (1, _d(mol=1), 1),
    "cd": (1, _d(cd=1), 1),
    "Hz": (1, _d(s=-1), 1),
    "N": (1, _d(m=1, kg=1, s=-2), 1),
    "Pa": (1, _d(m=-1, kg=1, s=-2), 1),
    "bar": (1e5, _d(m=-1, kg=1, s=-2), 1),
    "J": (1, _d(m=2, kg=1, s=-2), 1),
    "eV": (1.602176634e-19, _d(m=2, kg=1, s=-2), 1),
    "W": (1, _d(m=2, kg=1, s=-3), 1),
    "C": (1, _d(s=1, a=1), 1),
    "V": (1, _d(m=2, kg=1, s=-3, a=-1), 1),
    "F": (1, _d(m=-2, kg=-1, s=4, a=2), 1),
    "Ohm": (1, _d(m=2, kg=1, s=-3, a=-2), 1),
    "S": (1, _d(m=-2, kg=-1, s=3, a=2), 1),
    "Wb": (1, _d(m=2, kg=1, s=-2, a=-1), 1),
    "T": (1, _d(kg=1, s=-2, a=-1), 1),
    "H": (1, _d(m=2, kg=1, s=-2, a=-2), 1),
    "lm": (1, _d(cd=1), 1),
    "lx": (1, _d(m=-2, cd=1), 1),
    "Bq": (1, _d(s=-1), 1),
    "Gy": (1, _d(m=2, s=-2), 1),
    "Sv": (1, _d(m=2, s=-2), 1),
    "bit": (1, _d(bit=1), 4),
    "B": (8, _d(bit=1), 4),
    "t": (1000, _d(kg=1), 2),
    "r": (2 * _PI, NONE, 2),
    "Bd": (1, _d(s=-1), 2),
    "L": (0.001, _d(m=3), 3),
    "degC": (1, _d(k=1), 3),
    "rad": (1, NONE, 3),
    "deg": (_PI / 180, NONE, 3),
    "arcmin": (_PI / 10800, NONE, 3),
    "arcsec": (_PI / 648000, NONE, 3),
    "sr": (1, NONE, 3),
    "Np": (1, NONE, 3),
    "AU": (149597870700, _d(m=1), 0),
    "pc": (3.0856775814913673e16, _d(m=1), 0),
    "u": (1.66053906660e-27, _d(kg=1), 0),
    "min": (60, TIME, 0),
    "h": (3600, TIME, 0),
    "d": (86400, TIME, 0),
    "dB": (1, NONE, 0),
}
_MULT = {"Y": 1e24, "Z": 1e21, "E": 1e18, "P": 1e15, "T": 1e12, "G": 1e9, "M": 1e6, "k": 1e3,
         "h": 1e2, "da": 1e1}  # fmt: skip
_SUB = {"d": 1e-1, "c": 1e-2, "m": 1e-3, "u": 1e-6, "n": 1e-9, "p": 1e-12, "f": 1e-15,
        "a": 1e-18, "z": 1e-21, "y": 1e-24}  # fmt: skip
_BIN = {"Ki": 1024, "Mi": 1 << 20, "Gi": 1 << 30, "Ti": 1 << 40, "Pi": 1 << 50, "Ei": 1 << 60}
_OFFSET = {"degC": 273.15}


def symbol(word):
    """(scale, dims) of one Annex B unit symbol with its prefix, or None."""
    u = _UNITS.get(word)
    if u:
        return u[0], u[1]
    for n in (2, 1):
        p, rest = word[:n], word[n:]
        u = _UNITS.get(rest)
        if not u or not rest:
            continue
        cls = u[2]
        f = None
        if cls in (1, 2, 4) and p in _MULT:
            f = _MULT[p]
        if cls in (1, 3) and p in _SUB:
            f = _SUB[p]
        if cls == 4 and p in _BIN:
            f = _BIN[p]
        if f:
            return u[0] * f, u[1]
    return None


def _dmul(a, b, k=1):
    return tuple(a[i] + k * b[i] for i in range(_N))


class _UnitParser:
    def __init__(self, text):
        self.t = text
        self.i = 0

    def peek(self):
        return self.t[self.i] if self.i < len(self.t) else ""

    def ref(self):
        s, d = self.product()
        if self.peek() == "/":
            self.i += 1
            s2, d2 = self.factor()
            s, d = s / s2, _dmul(d, d2, -1)
        return s, d

    def product(self):
        s, d = self.factor()
        while self.peek() == ".":
            self.i += 1
            s2, d2 = self.factor()
            s, d = s * s2, _dmul(d, d2)
        return s, d

    def factor(self):
        if self.peek() == "(":
            self.i += 1
            s, d = self.ref()
            if self.peek() != ")":
                raise UnitError("unit %r: expected ')'" % self.t)
            self.i += 1
        else:
            j = self.i
            while self.i < len(self.t) and self.t[self.i].isalpha():
                self.i += 1
            sym = symbol(self.t[j : self.i])
            if sym is None:
                raise UnitError("unknown unit %r in %r" % (self.t[j : self.i], self.t))
            s, d = sym
        if self.peek() == "^":
            self.i += 1
            e = self.exponent()
            s, d = s**e, tuple(int(x * e) for x in d)
        return s, d

    def exponent(self):
        paren = self.peek() == "("
        if paren:
            self.i += 1
        sign = 1
        if self.peek() == "-":
            sign, self.i = -1, self.i + 1
        j = self.i
        while isdigits(self.peek()):
            self.i += 1
        if j == self.i:
            raise UnitError("unit %r: expected an exponent" % self.t)
        e = int(self.t[j : self.i])
        if paren:
            if self.peek() == "/":
                self.i += 1
                j = self.i
                while isdigits(self.peek()):
                    self.i += 1
                e = e / int(self.t[j : self.i] or "1")
            if self.peek() != ")":
                raise UnitError("unit %r: expected ')'" % self.t)
            self.i += 1
        return sign * e


_cache = {}


def parse(text):
    """(scale to SI, dims) of a unit text such as "km/s", "m.s^-2", "[V]"; raises UnitError."""
    r = _cache.get(text)
    if r is None:
        t = text[1:-1] if text[:1] == "[" and text[-1:] == "]" else text
        p = _UnitParser(t)
        r = p.ref()
        if p.i != len(t):
            raise UnitError("unit %r: unexpected %r" % (text, t[p.i :]))
        _cache[text] = r
    return r


def dims(text):
    return parse(text)[1] if text else NONE


# this interpreter's float: double on CPython and the unix port, single on a board, where
# 1/1e-3 is 999.99994: a change of decimal prefix is rounded to the digits the float holds
_SINGLE = 1.0 + 1e-9 == 1.0
_DIGITS = "%.6g" if _SINGLE else "%.15g"
_EPS = 1e-6 if _SINGLE else 1e-12


def _decimal(ratio):
    """True when ``ratio`` is a power of ten (a change of decimal prefix only), to the
    precision of the interpreter's float."""
    p = 1.0
    n = 0
    while p < ratio * (1 - _EPS) and n < 40:  # no float literal beyond single precision
        p *= 10
        n += 1
    return abs(p - ratio) <= _EPS * p


class Quantity:
    """A number with an engineering unit: ``Quantity(5, "V")``."""

    def __init__(self, value, unit):
        self.value = value
        self.unit = unit

    def si(self):
        return self.value * parse(self.unit)[0] + _OFFSET.get(self.unit, 0)

    def to(self, unit):
        """The same quantity expressed in ``unit`` (dimensions must agree)."""
        if unit == self.unit:
            return self
        s1, d1 = parse(self.unit)
        s2, d2 = parse(unit)
        if d1 != d2:
            raise UnitError("cannot convert %s to %s" % (self.unit, unit))
        off = _OFFSET.get(self.unit, 0) - _OFFSET.get(unit, 0)
        ratio = s1 / s2 if s1 >= s2 else s2 / s1
        if off:
            v = (self.value * s1 + off) / s2
        elif s1 >= s2:
            v = self.value * ratio
        else:
            v = self.value / ratio
        if not off and type(v) is float and v - v == 0 and _decimal(ratio):
            # decimal prefixes are not exact in binary: 3300 mV is 3.3 V, not 3.3000000000000003
            v = float(_DIGITS % v)
        if type(self.value) is int and v == int(v):
            v = int(v)
        return Quantity(v, unit)

    def __eq__(self, other):
        return isinstance(other, Quantity) and compare(self, other) == 0

    def __repr__(self):
        return "Quantity(%r, %r)" % (self.value, self.unit)

    def __str__(self):
        return "%s %s" % (fmt_num(self.value), self.unit)


def fmt_num(v):
    if type(v) is float and v == int(v) and abs(v) < 1e15:
        return str(int(v)) + ".0"
    return str(v)


# Absolute times are seconds since 1970-01-01T00:00:00Z (UTC, no leap seconds).
def _days_from_civil(y, m, d):
    y -= m <= 2
    era = (y if y >= 0 else y - 399) // 400
    yoe = y - era * 400
    doy = (153 * (m + (-3 if m > 2 else 9)) + 2) // 5 + d - 1
    doe = yoe * 365 + yoe // 4 - yoe // 100 + doy
    return era * 146097 + doe - 719468


def _civil_from_days(z):
    z += 719468
    era = (z if z >= 0 else z - 146096) // 146097
    doe = z - era * 146097
    yoe = (doe - doe // 1460 + doe // 36524 - doe // 146096) // 365
    doy = doe - (365 * yoe + yoe // 4 - yoe // 100)
    mp = (5 * doy + 2) // 153
    d = doy - (153 * mp + 2) // 5 + 1
    m = mp + (3 if mp < 10 else -9)
    return yoe + era * 400 + (m <= 2), m, d


def civil(days):
    """(year, month, day) of a day count since 1970-01-01."""
    return _civil_from_days(days)


def days_from_civil(y, m, d):
    """Day count since 1970-01-01 of a date of the proleptic Gregorian calendar."""
    return _days_from_civil(y, m, d)


class AbsTime:
    """An absolute time: seconds since 1970-01-01T00:00:00Z."""

    def __init__(self, seconds):
        self.seconds = seconds

    def __eq__(self, other):
        return isinstance(other, AbsTime) and other.seconds == self.seconds

    def __repr__(self):
        return "AbsTime(%r)" % self.seconds

    def __str__(self):
        return iso(self.seconds)


def iso(seconds):
    """ISO-8601 text (``2024-05-01T12:00:00.000Z``) of seconds since the Unix epoch."""
    whole = int(seconds // 1)
    ms = int(round((seconds - whole) * 1000))
    if ms >= 1000:
        whole, ms = whole + 1, ms - 1000
    days, rem = divmod(whole, 86400)
    y, mo, d = _civil_from_days(days)
    return "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ" % (
        y, mo, d, rem // 3600, rem // 60 % 60, rem % 60, ms)  # fmt: skip


def _field(text, lo, hi):
    """An unsigned decimal field within lo..hi (ValueError otherwise, also for '' or '+1')."""
    if not text or not isdigits(text) or len(text) > 9:
        raise ValueError
    v = int(text)
    if not lo <= v <= hi:
        raise ValueError
    return v


_MONTH_DAYS = (31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31)


def parse_iso(text):
    """Seconds since the Unix epoch of ``YYYY-MM-DDThh:mm:ss[.f][Z]`` or ``YYYY-DDDThh:mm:ss``;
    every field checked against its range (a leap second, ss = 60, is taken)."""
    t = text[:-1] if text.endswith("Z") else text
    try:
        date, clock = t.split("T")
        parts = date.split("-")
        if len(parts[0]) != 4:
            raise ValueError
        year = _field(parts[0], 1, 9999)
        if len(parts) == 3:
            month = _field(parts[1], 1, 12)
            days = _days_from_civil(year, month, _field(parts[2], 1, _MONTH_DAYS[month - 1]))
        elif len(parts) == 2:
            days = _days_from_civil(year, 1, 1) + _field(parts[1], 1, 366) - 1
        else:
            raise ValueError
        hms = clock.split(":")
        if len(hms) != 3:
            raise ValueError
        sec = hms[2]
        frac = 0
        if "." in sec:
            sec, f = sec.split(".")
            if not f or not isdigits(f) or len(f) > 9:
                raise ValueError
            frac = int(f) / 10 ** len(f)
        whole = days * 86400 + _field(hms[0], 0, 23) * 3600 + _field(hms[1], 0, 59) * 60
        whole += _field(sec, 0, 60)
    except (ValueError, IndexError):
        raise UnitError("not an absolute time: %r" % text) from None
    return whole + frac if frac else whole


def seconds(v):
    """Seconds of a relative time (a Quantity with a time unit, or a plain number)."""
    if isinstance(v, Quantity):
        return v.to("s").value
    return v


def compare(a, b):
    """-1, 0 or 1; quantities are compared after conversion to the left operand's unit."""
    if isinstance(a, Quantity):
        b = b.to(a.unit).value if isinstance(b, Quantity) else b
        a = a.value
    elif isinstance(b, Quantity):
        b = b.value
    elif isinstance(a, AbsTime):
        if not isinstance(b, AbsTime):
            raise UnitError("cannot compare an absolute time with %r" % (b,))
        a, b = a.seconds, b.seconds
    return (a > b) - (a < b)


def _q(v, unit, d):
    if d == NONE and unit is not None:
        return v * parse(unit)[0] if parse(unit)[0] != 1 else v
    return Quantity(v, unit)


def arith(op, a, b):
    """``a op b`` for op in + - * / ** on numbers, quantities and absolute times."""
    qa, qb = isinstance(a, Quantity), isinstance(b, Quantity)
    if isinstance(a, AbsTime) or isinstance(b, AbsTime):
        return _time_arith(op, a, b)
    if op == "+" or op == "-":
        if qa or qb:
            if qa and qb:
                bv = b.to(a.unit).value
                return Quantity(a.value + bv if op == "+" else a.value - bv, a.unit)
            q, n = (a, b) if qa else (b, a)
            if dims(q.unit) != NONE:
                raise UnitError("cannot add %s and a plain number" % q.unit)
            a, b = (q.si(), n) if qa else (n, q.si())
        return a + b if op == "+" else a - b
    if op == "**":
        if qb:
            if dims(b.unit) != NONE:
                raise UnitError("exponent has unit %s" % b.unit)
            b = b.si()
        if qa:
            if b != int(b):
                raise UnitError("fractional power of %s" % a.unit)
            return _q(a.value**b, _wrap(a.unit, "/.^") + "^" + str(int(b)), _scale(a.unit, b))
        return a**b
    av, au = (a.value, a.unit) if qa else (a, None)
    bv, bu = (b.value, b.unit) if qb else (b, None)
    if op == "*":
        v = av * bv
        if au and bu:
            u = _wrap(au) + "." + _wrap(bu)
            return _q(v, u, _dmul(dims(au), dims(bu)))
    else:
        v = av / bv
        if bu:
            if au:
                return _q(v, _wrap(au) + "/" + _wrap(bu, "/.^"), _dmul(dims(au), dims(bu), -1))
            return _q(v, _wrap(bu, "/.^") + "^-1", _scale(bu, -1))
    u = au or bu
    return Quantity(v, u) if u else v


def _scale(unit, e):
    return tuple(int(x * e) for x in dims(unit))


def _wrap(u, chars="/"):
    for c in chars:
        if c in u:
            return "(" + u + ")"
    return u


def _time_arith(op, a, b):
    ta, tb = isinstance(a, AbsTime), isinstance(b, AbsTime)
    if op == "-" and ta and tb:
        return Quantity(a.seconds - b.seconds, "s")
    if op == "+" and ta and not tb:
        return AbsTime(a.seconds + seconds(b))
    if op == "+" and tb and not ta:
        return AbsTime(b.seconds + seconds(a))
    if op == "-" and ta:
        return AbsTime(a.seconds - seconds(b))
    raise UnitError("cannot apply %s to absolute times" % op)


def neg(a):
    if isinstance(a, Quantity):
        return Quantity(-a.value, a.unit)
    return -a


def text(v):
    """The text PLUTO log and inform user statements show for a value."""
    if v is True:
        return "TRUE"
    if v is False:
        return "FALSE"
    if isinstance(v, AbsTime):
        return iso(v.seconds)
    if type(v) is float:
        return fmt_num(v)
    return str(v)
