"""TAI seconds since 1958-01-01 (the CCSDS epoch) to and from UTC calendar dates and text."""

from obsw.timecode import TimeCodeFormatError

# (days from 1958-01-01 to the UTC date from which it applies, TAI-UTC in seconds), from
# 1972-01-01 (TAI-UTC = 10 s) to the latest leap second (2017-01-01, 37 s). Before 1972 UTC
# had fractional offsets; they are approximated by 10 s.
LEAP_SECONDS = (
    (5113, 10),
    (5295, 11),
    (5479, 12),
    (5844, 13),
    (6209, 14),
    (6574, 15),
    (6940, 16),
    (7305, 17),
    (7670, 18),
    (8035, 19),
    (8582, 20),
    (8947, 21),
    (9312, 22),
    (10043, 23),
    (10957, 24),
    (11688, 25),
    (12053, 26),
    (12600, 27),
    (12965, 28),
    (13330, 29),
    (13879, 30),
    (14426, 31),
    (14975, 32),
    (17532, 33),
    (18628, 34),
    (19905, 35),
    (21000, 36),
    (21550, 37),
)


def days_from_civil(y, m, d):
    """Days from 1958-01-01 to the given proleptic Gregorian date."""
    y -= m <= 2
    era = y // 400
    yoe = y - era * 400
    doy = (153 * (m + (-3 if m > 2 else 9)) + 2) // 5 + d - 1
    doe = yoe * 365 + yoe // 4 - yoe // 100 + doy
    return era * 146097 + doe - 715085  # 715085: 1958-01-01 counted from 0000-03-01


def civil_from_days(days):
    """(year, month, day) ``days`` after 1958-01-01."""
    z = days + 715085
    era = z // 146097
    doe = z - era * 146097
    yoe = (doe - doe // 1460 + doe // 36524 - doe // 146096) // 365
    doy = doe - (365 * yoe + yoe // 4 - yoe // 100)
    mp = (5 * doy + 2) // 153
    d = doy - (153 * mp + 2) // 5 + 1
    m = mp + 3 if mp < 10 else mp - 9
    return yoe + era * 400 + (m <= 2), m, d


def _offset_for_day(days):
    off = 10
    for start, value in LEAP_SECONDS:
        if days < start:
            break
        off = value
    return off


def utc_to_tai(year, month, day, hour=0, minute=0, second=0):
    """TAI seconds since 1958-01-01 for a UTC date and time (second may be 60, or a float)."""
    days = days_from_civil(year, month, day)
    return days * 86400 + hour * 3600 + minute * 60 + second + _offset_for_day(days)


def tai_to_utc(tai):
    """(year, month, day, hour, minute, second) in UTC; second is 60.x in a leap second."""
    off = 10
    leap = False
    for start, value in LEAP_SECONDS:
        if tai < start * 86400 + value:
            # A step up by one: the second before the new offset is 23:59:60.
            leap = value == off + 1 and tai >= start * 86400 + value - 1
            break
        off = value
    utc = tai - off
    if leap:
        utc -= 1
    days = int(utc // 86400)
    rest = utc - days * 86400
    y, mo, d = civil_from_days(days)
    hour = int(rest // 3600)
    minute = int((rest - hour * 3600) // 60)
    second = rest - hour * 3600 - minute * 60
    if leap:
        second += 1
    return y, mo, d, hour, minute, second


def format_utc(tai, digits=3):
    """ISO 8601 UTC text ('2017-01-01T00:00:00.000Z') for TAI seconds since 1958."""
    y, mo, d, h, mi, s = tai_to_utc(tai)
    whole = int(s)
    if digits:
        frac = int((s - whole) * 10**digits + 0.5)
        if frac >= 10**digits:  # rounding carried; keep the simple form (no re-normalising)
            frac = 10**digits - 1
        return "%04d-%02d-%02dT%02d:%02d:%02d.%0*dZ" % (y, mo, d, h, mi, whole, digits, frac)
    return "%04d-%02d-%02dT%02d:%02d:%02dZ" % (y, mo, d, h, mi, whole)


def parse_utc(text):
    """TAI seconds since 1958 for 'YYYY-MM-DDTHH:MM:SS[.fff][Z]' (or a space for 'T')."""
    t = text.strip()
    if t.endswith("Z"):
        t = t[:-1]
    try:
        date, _, clock = t.replace(" ", "T").partition("T")
        y, mo, d = (int(x) for x in date.split("-"))
        parts = clock.split(":") if clock else ["0", "0", "0"]
        h, mi = int(parts[0]), int(parts[1])
        s = float(parts[2]) if "." in parts[2] else int(parts[2])
    except (ValueError, IndexError):
        msg = "not a UTC time 'YYYY-MM-DDTHH:MM:SS': %r" % text
        raise TimeCodeFormatError(msg, text) from None
    return utc_to_tai(y, mo, d, h, mi, s)
