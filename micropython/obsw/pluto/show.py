"""PLUTO expressions written back as procedure text, for messages that name what they reject."""

from obsw.pluto.units import NONE, Quantity, text

_SI = ("m", "kg", "s", "A", "K", "mol", "cd", "bit")
_MAX = 48  # characters of expression text in a message


def unit_text(dims):
    """SI base units of a dimension vector ("m.s^-1"), "" when dimensionless."""
    if dims is None or dims == NONE:
        return ""
    out = []
    for i, k in enumerate(dims):
        if k:
            out.append(_SI[i] if k == 1 else "%s^%d" % (_SI[i], k))
    return ".".join(out)


def source(e, depth=0):
    """Procedure text of expression node ``e`` (shortened; bounded recursion)."""
    try:
        s = _source(e, depth)
    except RuntimeError:  # called at the deepest nesting a board's C stack holds
        return "the expression"
    return s if len(s) <= _MAX else s[: _MAX - 3] + "..."


def _source(e, depth):
    if depth > 3:
        return "..."
    k = e[0]
    if k == "c":
        v = e[2]
        return '"%s"' % v if isinstance(v, str) else text(v)
    if k == "r":
        return " of ".join(e[2])
    if k == "f":
        return "%s(%s)" % (e[2], ", ".join([_source(a, depth + 1) for a in e[3]]))
    if k == "b" or k == "l":
        return "%s %s %s" % (_source(e[3], depth + 1), e[2], _source(e[4], depth + 1))
    if k == "cmp":
        return "%s %s %s" % (_source(e[3], depth + 1), e[2], _source(e[4], depth + 1))
    if k == "u":
        sep = " " if e[2] == "NOT" else ""
        return "%s%s%s" % (e[2], sep, _source(e[3], depth + 1))
    if k == "subj":
        return "the case subject"
    return "the expression"


def operand(e, unit=None, value=None):
    """How a message names an operand: "3 m", "speed (deg/s)", "speed (5 deg/s)"."""
    s = source(e)
    if e[0] == "c":
        return s
    if value is not None:
        return "%s (%s)" % (s, '"%s"' % value if isinstance(value, str) else text(value))
    return "%s (%s)" % (s, unit) if unit else s


def unit_of_value(v):
    return v.unit if isinstance(v, Quantity) else ""
