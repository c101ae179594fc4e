"""The mission's orbit: a two-line element set, its checksums and its epoch, read strictly.

``parse(lines)`` returns a ``Tle`` or raises ``TleError`` saying what was expected; the orbit
is propagated by ``sgp4`` (``Tle.satrec()``), which itself checks little.
"""

import datetime

UTC = datetime.timezone.utc


class TleError(ValueError):
    """A TLE that cannot be the mission's orbit; the message says what was expected."""


def checksum(line):
    """The TLE checksum of a line's first 68 characters: digits count, '-' counts one."""
    return sum(int(c) if c.isdigit() else (1 if c == "-" else 0) for c in line[:68]) % 10


def epoch_of(line1):
    """The epoch of line 1 (columns 19-32: two-digit year, day of year with fraction), UTC."""
    field = line1[18:32]
    try:
        yy = int(field[:2])
        day = float(field[2:])
    except ValueError:
        raise TleError(
            "epoch %r in columns 19-32 of line 1; expected YYDDD.DDDDDDDD" % field
        ) from None
    if not 1 <= day < 367:
        raise TleError("epoch day %r of line 1; expected 1 to 366.99999999" % field[2:])
    year = 1900 + yy if yy >= 57 else 2000 + yy  # the TLE convention: 57-99 are 1957-1999
    start = datetime.datetime(year, 1, 1, tzinfo=UTC)
    # to the microsecond: the field's 8 decimals of a day are 0.864 ms
    return start + datetime.timedelta(microseconds=round((day - 1) * 86400e6))


def parse_time(text):
    """An ISO 8601 UTC time 'YYYY-MM-DDTHH:MM:SS[.fff]Z' as an aware datetime."""
    if not isinstance(text, str) or not text.endswith("Z"):
        raise TleError("time %r; expected UTC as YYYY-MM-DDTHH:MM:SS[.fff]Z" % (text,))
    try:
        t = datetime.datetime.fromisoformat(text[:-1])
    except ValueError:
        raise TleError("time %r; expected UTC as YYYY-MM-DDTHH:MM:SS[.fff]Z" % (text,)) from None
    return t.replace(tzinfo=UTC)


def format_time(t):
    """An aware datetime as 'YYYY-MM-DDTHH:MM:SS.fffZ' (milliseconds)."""
    return t.astimezone(UTC).strftime("%Y-%m-%dT%H:%M:%S.%f")[:-3] + "Z"


class Tle:
    """A checked two-line element set: ``line1``, ``line2``, ``epoch`` (aware UTC), ``name``."""

    def __init__(self, line1, line2, name=None):
        self.line1 = line1
        self.line2 = line2
        self.name = name
        self.epoch = epoch_of(line1)
        self.catalog = line1[2:7].strip()

    def satrec(self):
        from sgp4.api import Satrec

        return Satrec.twoline2rv(self.line1, self.line2)

    @property
    def mean_motion(self):
        """Revolutions per day (line 2, columns 53-63)."""
        return float(self.line2[52:63])


def parse(lines, name=None):
    """``lines``: [line1, line2]; returns the ``Tle`` or raises ``TleError``."""
    if not isinstance(lines, (list, tuple)) or len(lines) != 2:
        raise TleError("%r; expected two lines" % (lines,))
    for n, line in enumerate(lines, 1):
        if not isinstance(line, str) or len(line) != 69:
            size = len(line) if isinstance(line, str) else "no"
            raise TleError("line %d has %s characters; expected 69" % (n, size))
        if line[0] != str(n) or line[1] != " ":
            raise TleError("line %d starts %r; expected '%d '" % (n, line[:2], n))
        if not line[68].isdigit() or int(line[68]) != checksum(line):
            raise TleError("line %d checksum %r; expected %d" % (n, line[68], checksum(line)))
    if lines[0][2:7] != lines[1][2:7]:
        raise TleError("catalog numbers %r and %r; expected the same object on both lines"
                       % (lines[0][2:7], lines[1][2:7]))  # fmt: skip
    tle = Tle(lines[0], lines[1], name)
    try:
        motion = tle.mean_motion
    except ValueError:
        text = lines[1][52:63]
        raise TleError("mean motion %r of line 2; expected revolutions per day" % text) from None
    if not 0 < motion < 20:
        raise TleError("mean motion %.4f rev/day; expected an Earth orbit (0 to 20)" % motion)
    sat = tle.satrec()
    if sat.error:
        raise TleError("sgp4 refuses the elements (error %d); expected a valid orbit" % sat.error)
    return tle
