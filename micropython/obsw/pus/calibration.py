"""Raw and engineering values of a parameter: calibrations, enumeration labels and ranges.

A parameter's ``type`` is its raw value, the one PUS packets carry. Its ``calibration`` turns
a raw value into an engineering value in ``unit``:

    {"polynomial": [c0, c1, c2]}                 eng = c0 + c1*raw + c2*raw**2
    {"polynomial": [{"coefficient": c, "exponent": e}, ..]}      (XTCE PolynomialCalibrator)
    {"spline": [[raw, eng], ..]}                 point pairs, linear interpolation between them
    {"spline": [{"raw": r, "calibrated": e}, ..], "order": 0 | 1, "extrapolate": false}
                                                 (XTCE SplineCalibrator: order 0 holds the
                                                 lower point's value; extrapolate extends the
                                                 end segments)

The inverse (engineering to raw) is exact for polynomials of degree 1 and for order-1 splines
whose engineering values are strictly monotonic; for every other calibration (degree 0 or 2 and
more, order 0, a spline that rises and falls) there is no unique raw value, and ``to_raw``
raises ``NotInvertibleError``: give raw values instead. A raw value outside a spline's points
(without ``extrapolate``) has no engineering value: ``CalibrationError``.

``enumeration`` labels raw values (``{"0": "OFF", "1": "ON"}`` or ``[{"value": 0, "label":
"OFF"}, ..]``); ``range`` is ``[low, high]`` in engineering units (the values a set may give);
``limits`` is ``{"warning": [low, high], "critical": [low, high]}`` in engineering units.
"""

# Relative slack of comparisons with engineering values: a board computes calibrations in single
# precision (about 7 digits), so a raw value at the edge of a range or limit may calibrate a few
# units in the 7th digit outside it; it still counts as inside.
_SLACK = 1e-6


def _slack(x):
    return _SLACK * (abs(x) if abs(x) > 1 else 1)


class CalibrationError(ValueError):
    """A calibration, enumeration, range or limits entry that is malformed, or a value it
    cannot convert."""


class NotInvertibleError(CalibrationError):
    """An engineering value whose calibration has no unique raw value."""


def _number(x, what):
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        raise CalibrationError("%s: expected a number, got %r" % (what, x))
    return x


class Polynomial:
    """eng = sum(c[i] * raw**i)."""

    def __init__(self, coefficients):
        self.coefficients = coefficients  # c0 first
        while len(self.coefficients) > 1 and self.coefficients[-1] == 0:
            self.coefficients = self.coefficients[:-1]

    @property
    def degree(self):
        return len(self.coefficients) - 1

    def engineering(self, raw):
        v = 0.0
        for c in reversed(self.coefficients):
            v = v * raw + c
        return v

    def raw(self, eng):
        if self.degree != 1:
            raise NotInvertibleError(
                "a polynomial of degree %d has no unique inverse: give the raw value" % self.degree
            )
        c0, c1 = self.coefficients
        return (eng - c0) / c1

    def increasing(self):
        return self.degree != 1 or self.coefficients[1] > 0

    def spec(self):
        return {"polynomial": list(self.coefficients)}


class Spline:
    """Point pairs (raw, eng) sorted by raw; ``order`` 1 interpolates linearly, 0 steps."""

    def __init__(self, points, order=1, extrapolate=False):
        self.points = points
        self.order = order
        self.extrapolate = extrapolate

    def _segment(self, x, key):
        pts = self.points
        for i in range(len(pts) - 1):
            a, b = pts[i][key], pts[i + 1][key]
            if min(a, b) <= x <= max(a, b):
                return i
        return None

    def engineering(self, raw):
        pts = self.points
        if raw < pts[0][0] or raw > pts[-1][0]:
            if not self.extrapolate:
                raise CalibrationError(
                    "raw value %r outside the calibration's points [%r, %r]"
                    % (raw, pts[0][0], pts[-1][0])
                )
            i = 0 if raw < pts[0][0] else len(pts) - 2
        else:
            i = self._segment(raw, 0)
        (r0, e0), (r1, e1) = pts[i], pts[i + 1]
        if self.order == 0:
            return float(e1 if raw >= r1 else e0)
        return e0 + (e1 - e0) * (raw - r0) / (r1 - r0)

    def _monotonic(self):
        engs = [p[1] for p in self.points]
        up = all(engs[i] < engs[i + 1] for i in range(len(engs) - 1))
        down = all(engs[i] > engs[i + 1] for i in range(len(engs) - 1))
        return up or down

    def raw(self, eng):
        if self.order != 1 or not self._monotonic():
            raise NotInvertibleError(
                "this point-pair calibration has no unique inverse: give the raw value"
            )
        i = self._segment(eng, 1)
        if i is None:
            if not self.extrapolate:
                raise CalibrationError(
                    "engineering value %r outside the calibration's points" % (eng,)
                )
            first, last = self.points[0][1], self.points[-1][1]
            i = 0 if abs(eng - first) < abs(eng - last) else len(self.points) - 2
        (r0, e0), (r1, e1) = self.points[i], self.points[i + 1]
        return r0 + (r1 - r0) * (eng - e0) / (e1 - e0)

    def increasing(self):
        return self.points[-1][1] >= self.points[0][1]

    def spec(self):
        out = {"spline": [list(p) for p in self.points]}
        if self.order != 1:
            out["order"] = self.order
        if self.extrapolate:
            out["extrapolate"] = True
        return out


def _polynomial(terms, what):
    if not isinstance(terms, list) or not terms:
        raise CalibrationError("%s.polynomial: expected a list of coefficients" % what)
    if all(isinstance(t, dict) for t in terms):
        coeffs = {}
        for t in terms:
            e = t.get("exponent")
            if not isinstance(e, int) or isinstance(e, bool) or not 0 <= e <= 16 or e in coeffs:
                raise CalibrationError(
                    "%s.polynomial: exponent %r unusable or repeated" % (what, e)
                )
            coeffs[e] = _number(t.get("coefficient"), what + ".polynomial coefficient")
        return Polynomial([coeffs.get(i, 0) for i in range(max(coeffs) + 1)])
    return Polynomial([_number(c, what + ".polynomial") for c in terms])


def _spline(spec, what):
    raw = spec["spline"]
    if not isinstance(raw, list) or len(raw) < 2:
        raise CalibrationError("%s.spline: expected at least two points" % what)
    points = []
    for p in raw:
        if isinstance(p, dict):
            p = (p.get("raw"), p.get("calibrated"))
        if not isinstance(p, (list, tuple)) or len(p) != 2:
            raise CalibrationError("%s.spline: point %r, expected [raw, eng]" % (what, p))
        points.append((_number(p[0], what + ".spline raw"), _number(p[1], what + ".spline eng")))
    points.sort()
    for i in range(len(points) - 1):
        if points[i][0] == points[i + 1][0]:
            raise CalibrationError("%s.spline: raw value %r twice" % (what, points[i][0]))
    order = spec.get("order", 1)
    if order not in (0, 1):
        raise CalibrationError("%s.order: %r, expected 0 or 1" % (what, order))
    return Spline(points, order, bool(spec.get("extrapolate", False)))


def calibration(spec, what="calibration"):
    """The calibration of a database entry (see the module text), or None for none."""
    if spec is None:
        return None
    if not isinstance(spec, dict):
        raise CalibrationError("%s: expected an object, got %r" % (what, spec))
    if "polynomial" in spec:
        return _polynomial(spec["polynomial"], what)
    if "spline" in spec:
        return _spline(spec, what)
    raise CalibrationError("%s: expected 'polynomial' or 'spline', got %s" % (what, sorted(spec)))


def enumeration(spec, what="enumeration"):
    """{raw value: label} of a database entry, or None."""
    if spec is None:
        return None
    out = {}
    if isinstance(spec, dict):
        pairs = list(spec.items())
    elif isinstance(spec, list):
        pairs = []
        for e in spec:
            if not isinstance(e, dict):
                raise CalibrationError("%s: entry %r, expected {value, label}" % (what, e))
            pairs.append((e.get("value"), e.get("label")))
    else:
        raise CalibrationError("%s: expected an object or a list, got %r" % (what, spec))
    for value, label in pairs:
        try:
            v = int(value)
        except (TypeError, ValueError):
            raise CalibrationError("%s: value %r is not an integer" % (what, value)) from None
        if not isinstance(label, str) or not label:
            raise CalibrationError("%s: label of %d is %r, expected a name" % (what, v, label))
        if v in out or label in out.values():
            raise CalibrationError("%s: value %d or label %s given twice" % (what, v, label))
        out[v] = label
    return out


def bounds(spec, what):
    """A [low, high] pair of numbers (either may be null), or None."""
    if spec is None:
        return None
    if not isinstance(spec, (list, tuple)) or len(spec) != 2:
        raise CalibrationError("%s: %r, expected [low, high]" % (what, spec))
    low, high = spec
    if low is not None:
        _number(low, what)
    if high is not None:
        _number(high, what)
    if low is not None and high is not None and low > high:
        raise CalibrationError("%s: low %r above high %r" % (what, low, high))
    return (low, high)


LIMIT_LEVELS = ("watch", "warning", "distress", "critical", "severe")


def limits(spec, what="limits"):
    """{level: (low, high)} in engineering units, or None."""
    if spec is None:
        return None
    if not isinstance(spec, dict) or not spec:
        raise CalibrationError('%s: expected {"warning": [low, high], ..}' % what)
    out = {}
    for level, pair in spec.items():
        if level not in LIMIT_LEVELS:
            raise CalibrationError(
                "%s: level %r, expected one of %s" % (what, level, ", ".join(LIMIT_LEVELS))
            )
        out[level] = bounds(pair, "%s.%s" % (what, level))
    return out


class Values:
    """Raw <-> engineering conversion of one parameter: its field type ``ftype`` and the
    database's ``calibration``, ``enumeration`` and ``range`` entries (parsed here)."""

    def __init__(self, ftype, spec, what="parameter"):
        self.ftype = ftype
        self.calibration = calibration(spec.get("calibration"), what + ".calibration")
        self.labels = enumeration(spec.get("enumeration"), what + ".enumeration")
        self.range = bounds(spec.get("range"), what + ".range")
        self.limits = limits(spec.get("limits"), what + ".limits")
        if self.calibration is not None and ftype.ptc not in (2, 3, 4, 5):
            raise CalibrationError("%s.calibration: a calibration needs a numeric type" % what)
        if self.labels is not None and ftype.ptc not in (1, 2, 3, 4):
            raise CalibrationError("%s.enumeration: labels need an integer type" % what)
        if self.range is not None and ftype.ptc not in (2, 3, 4, 5):
            raise CalibrationError("%s.range: a range needs a numeric type" % what)

    @property
    def integer(self):
        return self.ftype.ptc in (1, 2, 3, 4)

    def engineering(self, raw):
        """The engineering value of ``raw``: calibrated, or its label, or raw itself."""
        if self.labels is not None:
            return self.labels.get(int(raw), raw)
        if self.calibration is not None:
            return self.calibration.engineering(raw)
        return raw

    def to_raw(self, eng):
        """The raw value of engineering value ``eng`` (a label, a number); integer types are
        rounded to the nearest integer. Raises CalibrationError."""
        if isinstance(eng, str) and self.labels is not None:
            for v, label in self.labels.items():
                if label == eng:
                    return v
            raise CalibrationError(
                "no label %r, expected one of %s" % (eng, ", ".join(self.labels.values()))
            )
        if self.calibration is None or isinstance(eng, (str, bool, bytes)) or eng is None:
            return eng
        raw = self.calibration.raw(eng)
        if self.integer:
            return int(raw + 0.5) if raw >= 0 else -int(-raw + 0.5)
        return raw

    def out_of_range(self, raw):
        """None if raw value ``raw`` is within ``range`` (engineering units), else why not."""
        if self.range is None:
            return None
        try:  # labels are not ordered: an enumeration's range is on its raw values
            eng = raw if self.calibration is None else self.calibration.engineering(raw)
        except CalibrationError as e:
            return str(e)
        if isinstance(eng, (str, bytes)):
            return "%r is not a number" % (eng,)
        low, high = self.range
        if (low is not None and eng < low - _slack(low)) or (
            high is not None and eng > high + _slack(high)
        ):
            return "%r outside the range [%s, %s]" % (eng, low, high)
        return None

    def raw_limits(self, low, high):
        """Engineering limits as raw limits for an on-board limit check: (raw_low, raw_high,
        swapped). For integer types the raw low limit is rounded up and the high one down, so
        that a raw value is out of the raw limits exactly when its engineering value is out
        of the engineering ones; a decreasing calibration swaps the two (``swapped``)."""
        cal = self.calibration
        swapped = False
        if cal is not None:
            low, high = cal.raw(low), cal.raw(high)
            swapped = not cal.increasing()
            if swapped:
                low, high = high, low
        if self.integer:
            low = -int(-(low - _slack(low)) // 1)  # ceil, a rounding error short of it too
            high = int((high + _slack(high)) // 1)  # floor
        return low, high, swapped

    def raw_limits_of(self, low, high):
        """Raw limits as given, checked to fit the raw type (integers for integer types)."""
        if not self.integer:
            return low, high
        for x in (low, high):
            if x != int(x):
                raise CalibrationError("raw limit %r of an integer parameter" % (x,))
        return int(low), int(high)
