"""The core's errors: a family per protocol, a kind per mistake, one argument order per kind.

Every decoder raises the errors of its own family (``SppError``, ``PusError``, ``FrameError``,
``CfdpError``, ``TimeCodeError``, ...), all ``ValueError``: catch a family to catch whatever one
decoder refuses. Within every family a kind has one name ending, one argument order, the same
attributes and the same message:

- ``...TooShortError(what, needed, got)``: fewer octets (bits in ``obsw.bits``) than ``what``
  needs; the message is ``too_short(what, needed, got)``.
- ``...LengthError(what, expected, got)``: a length (a field, or what a format fixes) that does
  not match what arrived; the message is ``wrong_length(what, expected, got)``.
- ``UnknownNameError(kind, name, where, known)``: a name a table does not hold (a ``KeyError``),
  with the closest name it does hold.

A kind is a name, an argument order and a message, not a second base class: MicroPython gives an
exception class one exception base (two are refused with "multiple bases have instance lay-out
conflict").
"""


def too_short(what, needed, got, unit="bytes"):
    """The message of every ``...TooShortError``."""
    return "%s too short: %d %s, needs %d" % (what, got, unit, needed)


def wrong_length(what, expected, got, unit="bytes"):
    """The message of every ``...LengthError``."""
    return "%s length: %d %s, expected %d" % (what, got, unit, expected)


def closest(name, known):
    """The name of ``known`` closest to ``name`` (at most a third of it differs), or None."""
    best, best_d = None, len(name) // 3 + 1
    for k in known:
        d = _distance(name.lower(), k.lower())
        if d < best_d:
            best, best_d = k, d
    return best


def _distance(a, b):
    """Levenshtein distance of ``a`` and ``b``."""
    row = list(range(len(b) + 1))
    for i in range(1, len(a) + 1):
        diag, row[0] = row[0], i
        for j in range(1, len(b) + 1):
            cost = 0 if a[i - 1] == b[j - 1] else 1
            diag, row[j] = row[j], min(row[j] + 1, row[j - 1] + 1, diag + cost)
    return row[len(b)]


class UnknownNameError(KeyError):
    """``name`` is no ``kind`` (parameter, event, function, ...) of ``where``; ``suggestion`` is
    the closest name ``known`` holds, or None. ``str()`` is the one-line message."""

    def __init__(self, kind, name, where="the spacecraft database", known=()):
        self.kind = kind
        self.name = name
        self.suggestion = closest(str(name), [str(k) for k in known])
        hint = " (did you mean %r?)" % self.suggestion if self.suggestion is not None else ""
        self.message = "no %s %r in %s%s" % (kind, name, where, hint)
        super().__init__(self.message)

    def __str__(self):  # a KeyError's own str() quotes its argument
        return self.message
