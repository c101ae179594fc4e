"""XTCE data types for PUS packet field types (PTC, PFC), with units, ranges, alarms, calibrations.

``parameter_type`` and ``argument_type`` return one ElementTree element each; the caller puts
it in a ParameterTypeSet or ArgumentTypeSet. Element order follows the XTCE 1.2 schema.
"""

import xml.etree.ElementTree as ET

from obsw.pus.calibration import CalibrationError, Polynomial
from obsw.pus.calibration import calibration as parse_calibration
from obsw.pus.fields import field


class XtceTypeError(ValueError):
    """A field type that has no XTCE encoding here."""


def _sub(parent, tag, **attrs):
    return ET.SubElement(parent, tag, {k: str(v) for k, v in attrs.items()})


def bits_of(pair):
    """The size in bits of a fixed-size field type; (0, n) is a plain n-bit unsigned integer
    (packet header fields that have no PUS field type)."""
    if pair[0] == 0:
        return pair[1]
    return field(pair[0], pair[1]).bits


def _encoding(parent, pair, calibration=None):
    ptc, pfc = pair
    if ptc in (0, 1, 2, 3, 4):
        enc = _sub(
            parent,
            "IntegerDataEncoding",
            sizeInBits=bits_of(pair),
            encoding="twosComplement" if ptc == 4 else "unsigned",
        )
    elif ptc == 5:
        enc = _sub(parent, "FloatDataEncoding", sizeInBits=bits_of(pair), encoding="IEEE754_1985")
    else:
        raise XtceTypeError("no numeric XTCE encoding for PTC %d PFC %d" % pair)
    if calibration:
        _calibrator(_sub(enc, "DefaultCalibrator"), calibration)
    return enc


def _calibrator(parent, spec):
    """A PolynomialCalibrator or SplineCalibrator for any shape ``obsw.pus.calibration``
    reads (coefficient lists or XTCE terms, point pairs or XTCE points, order, extrapolate)."""
    try:
        cal = parse_calibration(spec)
    except CalibrationError as e:
        raise XtceTypeError(str(e)) from None
    if isinstance(cal, Polynomial):
        poly = _sub(parent, "PolynomialCalibrator")
        for exponent, coefficient in enumerate(cal.coefficients):
            _sub(poly, "Term", coefficient=repr(float(coefficient)), exponent=exponent)
        return
    spline = _sub(parent, "SplineCalibrator")
    if cal.order != 1:
        spline.set("order", str(cal.order))
    if cal.extrapolate:
        spline.set("extrapolate", "true")
    for raw, eng in cal.points:
        _sub(spline, "SplinePoint", raw=repr(float(raw)), calibrated=repr(float(eng)))


def linear(spec):
    """True if calibration ``spec`` is a polynomial of degree 1 (Yamcs can reverse it for a
    command argument)."""
    try:
        cal = parse_calibration(spec)
    except CalibrationError:
        return False
    return isinstance(cal, Polynomial) and cal.degree == 1


def _units(parent, unit):
    units = _sub(parent, "UnitSet")
    if unit:
        ET.SubElement(units, "Unit").text = unit


def _string_encoding(parent, length_bits):
    enc = _sub(parent, "StringDataEncoding", encoding="UTF-8")
    var = _sub(enc, "Variable", maxSizeInBits=8 * ((1 << length_bits) - 1))
    _sub(var, "LeadingSize", sizeInBitsOfSizeTag=length_bits)


def _range(value):
    lo, hi = value
    attrs = {}
    if lo is not None:
        attrs["minInclusive"] = repr(lo)
    if hi is not None:
        attrs["maxInclusive"] = repr(hi)
    return attrs


def _alarm(parent, limits):
    alarm = _sub(parent, "DefaultAlarm")
    ranges = _sub(alarm, "StaticAlarmRanges")
    for level in ("watch", "warning", "distress", "critical", "severe"):
        if level in limits:
            _sub(ranges, level.capitalize() + "Range", **_range(limits[level]))


def parameter_type(name, pair, unit=None, limits=None, calibration=None, labels=None, alarms=None):
    """A parameter type; ``labels`` {value: label} makes an enumeration, ``alarms`` {label:
    level} raises those enumeration states as alarms."""
    ptc, pfc = pair
    if labels is not None:
        t = ET.Element("EnumeratedParameterType", name=name)
        _units(t, unit)
        _encoding(t, pair)
        lst = _sub(t, "EnumerationList")
        for value, label in sorted(labels.items()):
            _sub(lst, "Enumeration", value=value, label=label)
        if alarms:
            alarm = _sub(t, "DefaultAlarm")
            states = _sub(alarm, "EnumerationAlarmList")
            for label, level in alarms.items():
                _sub(states, "EnumerationAlarm", alarmLevel=level, enumerationLabel=label)
        return t
    if ptc == 1:
        t = ET.Element("BooleanParameterType", name=name)
        _units(t, unit)
        _encoding(t, pair)
        return t
    if ptc == 8:
        t = ET.Element("StringParameterType", name=name)
        _units(t, unit)
        _string_encoding(t, 16 if pfc == 0 else 8)
        return t
    if ptc in (0, 2, 3, 4) and not calibration:
        size = bits_of(pair)
        t = ET.Element("IntegerParameterType", name=name, signed=str(ptc == 4).lower())
        t.set("sizeInBits", "32" if size <= 32 else "64")
    elif ptc in (2, 3, 4, 5):
        t = ET.Element("FloatParameterType", name=name, sizeInBits="64")
    else:
        raise XtceTypeError("parameter %s: no XTCE type for PTC %d PFC %d" % (name, ptc, pfc))
    _units(t, unit)
    _encoding(t, pair, calibration)
    if limits:
        _alarm(t, limits)
    return t


def _octets(tag, name, pair, length):
    """PTC 7 (octet string) as binary data: PFC > 0 is that many octets; PFC 0 is variable,
    as many octets as ``length`` says, the (tag, attribute, reference) of the parameter or
    argument just before it (Yamcs' XTCE reader takes a fixed or a dynamic size for binary
    data, not a leading size as for strings)."""
    t = ET.Element(tag, name=name)
    size = _sub(_sub(t, "BinaryDataEncoding"), "SizeInBits")
    if pair[1]:
        _sub(size, "FixedValue").text = str(8 * pair[1])
    else:
        ref_tag, attr, ref = length
        dynamic = _sub(size, "DynamicValue")
        _sub(dynamic, ref_tag, **{attr: ref})
        _sub(dynamic, "LinearAdjustment", slope="8")
    return t


def octets_type(name, pair, length_ref=None):
    """A PTC 7 parameter; a variable one after parameter ``length_ref``."""
    return _octets(
        "BinaryParameterType", name, pair, ("ParameterInstanceRef", "parameterRef", length_ref)
    )


def octets_argument_type(name, pair, length_arg=None):
    """A PTC 7 command argument; a variable one after argument ``length_arg``."""
    return _octets(
        "BinaryArgumentType", name, pair, ("ArgumentInstanceRef", "argumentRef", length_arg)
    )


def text_argument_type(name, length_bits=16):
    """A variable string argument: UTF-8 octets after a ``length_bits`` wide leading length."""
    t = ET.Element("StringArgumentType", name=name)
    _units(t, None)
    _string_encoding(t, length_bits)
    return t


def argument_type(name, pair, unit=None, valid=None, labels=None, calibration=None):
    """An argument type; ``valid`` (low, high) bounds the values a user may give; a linear
    ``calibration`` makes it an engineering value that Yamcs turns into the raw one."""
    ptc, pfc = pair
    if calibration is not None and ptc in (2, 3, 4, 5):
        t = ET.Element("FloatArgumentType", name=name, sizeInBits="64")
        _units(t, unit)
        _encoding(t, pair, calibration)
        if valid is not None:
            _sub(_sub(t, "ValidRangeSet"), "ValidRange", **_range(valid))
        return t
    if labels is not None:
        t = ET.Element("EnumeratedArgumentType", name=name)
        _units(t, unit)
        _encoding(t, pair)
        lst = _sub(t, "EnumerationList")
        for value, label in sorted(labels.items()):
            _sub(lst, "Enumeration", value=value, label=label)
        return t
    if ptc == 1:
        t = ET.Element("BooleanArgumentType", name=name)
        _units(t, unit)
        _encoding(t, pair)
        return t
    if ptc == 8:
        t = ET.Element("StringArgumentType", name=name)
        _units(t, unit)
        _string_encoding(t, 16 if pfc == 0 else 8)
        return t
    if ptc in (0, 2, 3, 4):
        t = ET.Element("IntegerArgumentType", name=name, signed=str(ptc == 4).lower())
        size = bits_of(pair)
        t.set("sizeInBits", "32" if size <= 32 else "64")
        _units(t, unit)
        _encoding(t, pair)
        if valid is None:
            bits = bits_of(pair)
            valid = (
                (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if ptc == 4 else (0, (1 << bits) - 1)
            )
        _sub(_sub(t, "ValidRangeSet"), "ValidRange", **_range(valid))
        return t
    if ptc == 5:
        t = ET.Element("FloatArgumentType", name=name, sizeInBits=str(bits_of(pair)))
        _units(t, unit)
        _encoding(t, pair)
        if valid is not None:
            _sub(_sub(t, "ValidRangeSet"), "ValidRange", **_range(valid))
        return t
    raise XtceTypeError("argument %s: no XTCE type for PTC %d PFC %d" % (name, ptc, pfc))
