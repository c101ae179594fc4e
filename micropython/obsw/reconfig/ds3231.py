"""DS3231 real-time clock: BCD time registers, alarm 1, oscillator-stop flag, temperature; and
its synchronisation with the OBC's onboard time from SpaceCAN UTC/SCET frames.

Time on this module is UTC as (day since 1958-01-01, millisecond of day), the fields of the
SpaceCAN UTC frame.
"""

from obsw.compat import const
from obsw.utc import civil_from_days, days_from_civil

_REG_TIME = const(0x00)
_REG_ALARM1 = const(0x07)
_REG_CONTROL = const(0x0E)
_REG_STATUS = const(0x0F)
_REG_TEMP = const(0x11)
_OSF = const(0x80)
_A1F = const(0x01)
_A1IE = const(0x01)
_INTCN = const(0x04)

ALARM_EVERY_SECOND = const(0)
ALARM_SECONDS = const(1)  # when seconds match
ALARM_MINUTES = const(2)  # minutes and seconds
ALARM_HOURS = const(3)  # hours, minutes and seconds
ALARM_DATE = const(4)  # date, hours, minutes and seconds


class RtcError(ValueError):
    """A register value that is not valid BCD for its field, or a date out of range."""

    def __init__(self, msg, value=None):
        super().__init__(msg)
        self.value = value


def to_bcd(v):
    if not 0 <= v <= 99:
        raise RtcError("BCD field takes 0..99, got %r" % (v,), v)
    return ((v // 10) << 4) | (v % 10)


def from_bcd(b, field="field"):
    hi = b >> 4
    lo = b & 0x0F
    if hi > 9 or lo > 9:
        raise RtcError("%s register 0x%02X is not BCD" % (field, b), b)
    return hi * 10 + lo


def encode_time(year, month, day, hour, minute, second, weekday=None):
    """The 7 time registers (24-hour mode, century bit for 2100..2199)."""
    if not 2000 <= year <= 2199:
        raise RtcError("DS3231 holds years 2000..2199, got %d" % year, year)
    if not (1 <= month <= 12 and 1 <= day <= 31 and hour < 24 and minute < 60 and second < 60):
        raise RtcError(
            "invalid date %04d-%02d-%02d %02d:%02d:%02d" % (year, month, day, hour, minute, second)
        )
    if weekday is None:
        weekday = (days_from_civil(year, month, day) + 2) % 7 + 1  # 1 = Monday
    return bytes(
        (
            to_bcd(second),
            to_bcd(minute),
            to_bcd(hour),
            weekday,
            to_bcd(day),
            to_bcd(month) | (0x80 if year >= 2100 else 0),
            to_bcd(year % 100),
        )
    )


def decode_time(regs):
    """(year, month, day, hour, minute, second, weekday) from the 7 time registers."""
    if len(regs) < 7:
        raise RtcError("DS3231 time needs 7 registers, got %d" % len(regs))
    h = regs[2]
    if h & 0x40:  # 12-hour mode: bit 5 is PM
        hour = from_bcd(h & 0x1F, "hour") % 12 + (12 if h & 0x20 else 0)
    else:
        hour = from_bcd(h & 0x3F, "hour")
    return (
        2000 + from_bcd(regs[6], "year") + (100 if regs[5] & 0x80 else 0),
        from_bcd(regs[5] & 0x1F, "month"),
        from_bcd(regs[4] & 0x3F, "date"),
        hour,
        from_bcd(regs[1] & 0x7F, "minute"),
        from_bcd(regs[0] & 0x7F, "second"),
        regs[3] & 0x07,
    )


def to_day_ms(t):
    """(day since 1958-01-01, ms of day) of a decoded time."""
    return days_from_civil(t[0], t[1], t[2]), ((t[3] * 60 + t[4]) * 60 + t[5]) * 1000


def from_day_ms(day, ms):
    y, mo, d = civil_from_days(day)
    s = ms // 1000
    return y, mo, d, s // 3600, (s // 60) % 60, s % 60


class DS3231:
    """Driver over a ``machine.I2C``-like bus."""

    def __init__(self, i2c, address=0x68):
        self.i2c = i2c
        self.address = address

    def _read(self, reg, n):
        return self.i2c.readfrom_mem(self.address, reg, n)

    def _write(self, reg, data):
        self.i2c.writeto_mem(self.address, reg, data)

    def datetime(self):
        return decode_time(self._read(_REG_TIME, 7))

    def set_datetime(self, year, month, day, hour, minute, second):
        """Set the time (restarts the seconds countdown) and clear the oscillator-stop flag."""
        self._write(_REG_TIME, encode_time(year, month, day, hour, minute, second))
        self.clear_oscillator_stop()

    def day_ms(self):
        return to_day_ms(self.datetime())

    def set_day_ms(self, day, ms):
        self.set_datetime(*from_day_ms(day, ms))

    def status(self):
        return self._read(_REG_STATUS, 1)[0]

    def oscillator_stopped(self):
        """True if the oscillator stopped since the flag was cleared (the time is not valid)."""
        return bool(self.status() & _OSF)

    def clear_oscillator_stop(self):
        self._write(_REG_STATUS, bytes((self.status() & ~_OSF & 0xFF,)))

    def temperature(self):
        """Degrees Celsius in 0.25 steps (10-bit two's complement)."""
        r = self._read(_REG_TEMP, 2)
        raw = (r[0] << 2) | (r[1] >> 6)
        if raw & 0x200:
            raw -= 0x400
        return raw / 4

    def set_alarm1(self, mode, second=0, minute=0, hour=0, date=1):
        """Alarm 1 on a match of the fields ``mode`` names; enables its interrupt on INT/SQW."""
        fields = (to_bcd(second), to_bcd(minute), to_bcd(hour), to_bcd(date))
        regs = bytearray(4)
        for i in range(4):
            masked = mode == ALARM_EVERY_SECOND or i >= mode
            regs[i] = fields[i] | (0x80 if masked else 0)
        self._write(_REG_ALARM1, regs)
        ctrl = self._read(_REG_CONTROL, 1)[0]
        self._write(_REG_CONTROL, bytes((ctrl | _INTCN | _A1IE,)))
        self.clear_alarm1()

    def alarm1_fired(self):
        return bool(self.status() & _A1F)

    def clear_alarm1(self):
        self._write(_REG_STATUS, bytes((self.status() & ~_A1F & 0xFF,)))


class TimeSync:
    """Keeps the DS3231 on the OBC's time. Sans-I/O: feed frames with ``now`` (seconds).

    A UTC frame whose time differs from the RTC by more than ``tolerance_ms`` (or any frame
    while the oscillator-stop flag is up) schedules a set at the next whole second, because
    writing the seconds register restarts the DS3231's countdown. SCET frames give the offset
    between spacecraft elapsed time and UTC, for reports in either scale.
    """

    def __init__(self, rtc, tolerance_ms=1500):
        self.rtc = rtc
        self.tolerance_ms = tolerance_ms
        self.pending = None  # (due time, day, ms) of a set waiting for the whole second
        self.scet_offset = None  # SCET seconds minus UTC seconds since 1958
        self.counters = {"utc": 0, "scet": 0, "sets": 0, "errors": 0}
        self.last_error_ms = None

    def on_utc(self, utc, now):
        self.counters["utc"] += 1
        try:
            stopped = self.rtc.oscillator_stopped()
            day, ms = self.rtc.day_ms()
        except (OSError, ValueError):
            self.counters["errors"] += 1
            stopped, day, ms = True, 0, 0
        obc = utc.day * 86400000 + utc.ms_of_day
        self.last_error_ms = day * 86400000 + ms - obc
        if not stopped and -self.tolerance_ms <= self.last_error_ms <= self.tolerance_ms:
            return False
        wait = (1000 - utc.ms_of_day % 1000) % 1000
        target = obc + wait
        self.pending = (now + wait / 1000, target // 86400000, target % 86400000)
        return True

    def on_scet(self, scet, now):
        self.counters["scet"] += 1
        try:
            day, ms = self.rtc.day_ms()
        except (OSError, ValueError):
            self.counters["errors"] += 1
            return
        self.scet_offset = scet.coarse_time - (day * 86400 + ms // 1000)

    def next_deadline(self):
        return None if self.pending is None else self.pending[0]

    def poll(self, now):
        p = self.pending
        if p is None or now < p[0]:
            return False
        self.pending = None
        late_ms = int((now - p[0]) * 1000) // 1000 * 1000  # whole seconds only
        ms = p[2] + late_ms
        try:
            self.rtc.set_day_ms(p[1] + ms // 86400000, ms % 86400000)
        except (OSError, ValueError):
            self.counters["errors"] += 1
            return False
        self.counters["sets"] += 1
        return True
