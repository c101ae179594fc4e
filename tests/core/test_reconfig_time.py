"""DS3231: BCD round trips, time registers, alarm, oscillator-stop flag, temperature; the
time synchronisation from SpaceCAN UTC and SCET frames; the TPS3813 window watchdog."""

import unittest

from obsw.reconfig import ds3231 as D
from obsw.reconfig.models import DS3231Model, ModelHal, SimI2C, Tps3813Model
from obsw.reconfig.watchdog import Watchdog, WatchdogConfigError
from obsw.spacecan.timeframes import ScetTime, UtcTime
from obsw.utc import days_from_civil


class Clock:
    def __init__(self):
        self.t = 0.0

    def __call__(self):
        return self.t


def rtc_rig(seconds=0):
    clock = Clock()
    i2c = SimI2C()
    model = DS3231Model(clock, seconds=seconds)
    i2c.devices[0x68] = model
    return clock, model, D.DS3231(i2c)


def _temp_file(name):
    import os

    base = (os.getenv("TMPDIR") if hasattr(os, "getenv") else None) or "/tmp"
    try:
        os.stat(base)
    except OSError:
        base = ""  # a board: its filesystem's top
    return (base.rstrip("/") + "/" if base else "") + name


class TestModelAcrossRestarts(unittest.TestCase):
    def test_the_clock_runs_on_in_whole_seconds_across_a_restart(self):
        import os

        path = _temp_file(
            "obsw-ds3231-model-%d.json" % (os.getpid() if hasattr(os, "getpid") else 0)
        )
        clock = Clock()
        clock.t = 1000.25
        try:
            first = DS3231Model(clock, path, seconds=2_000_000_000)
            first.write(0, first.read(0, 7))  # a set: the model keeps its state in the file
            clock.t += 7.5  # the controller restarts 7.5 s later, on the same wall clock
            again = DS3231Model(clock, path)
            self.assertEqual(again.seconds(), first.seconds())
            self.assertTrue(isinstance(again.seconds(), int))
            day, ms = D.DS3231(_one(again)).day_ms()  # readable: whole BCD fields
            self.assertEqual(day * 86400 + ms // 1000, again.seconds())
        finally:
            try:
                os.remove(path)
            except OSError:
                pass


def _one(model):
    i2c = SimI2C()
    i2c.devices[0x68] = model
    return i2c


class TestBcd(unittest.TestCase):
    def test_every_value_round_trips(self):
        for v in range(100):
            b = D.to_bcd(v)
            self.assertEqual(D.from_bcd(b), v)
            self.assertEqual(b, int(str(v), 16))

    def test_bad_values(self):
        with self.assertRaises(D.RtcError):
            D.to_bcd(100)
        with self.assertRaises(D.RtcError):
            D.from_bcd(0x1A)

    def test_time_registers_round_trip_over_two_centuries(self):
        day = days_from_civil(2000, 1, 1)
        end = days_from_civil(2199, 12, 31)
        step = 0
        while day <= end:
            ms = (step * 7919 % 86400) * 1000
            t = D.from_day_ms(day, ms)
            regs = D.encode_time(*t)
            back = D.decode_time(regs)
            self.assertEqual(back[:6], t)
            self.assertEqual(D.to_day_ms(back), (day, ms))
            self.assertEqual(back[6], (day + 2) % 7 + 1)
            day += 97
            step += 1
        regs = D.encode_time(2150, 2, 28, 23, 59, 58)
        self.assertEqual(regs[5] & 0x80, 0x80)  # century bit

    def test_twelve_hour_mode_and_range(self):
        regs = bytearray(D.encode_time(2024, 5, 6, 0, 0, 0))
        regs[2] = 0x40 | 0x20 | 0x11  # 12-hour mode, PM, 11 o'clock
        self.assertEqual(D.decode_time(regs)[3], 23)
        regs[2] = 0x40 | 0x12  # 12 AM is midnight
        self.assertEqual(D.decode_time(regs)[3], 0)
        with self.assertRaises(D.RtcError):
            D.encode_time(1999, 1, 1, 0, 0, 0)
        with self.assertRaises(D.RtcError):
            D.encode_time(2024, 13, 1, 0, 0, 0)


class TestDriver(unittest.TestCase):
    def test_set_read_and_oscillator_stop(self):
        clock, model, rtc = rtc_rig()
        self.assertTrue(rtc.oscillator_stopped())  # first power-up
        rtc.set_datetime(2025, 6, 30, 23, 59, 58)
        self.assertFalse(rtc.oscillator_stopped())
        clock.t = 3.2
        self.assertEqual(rtc.datetime()[:6], (2025, 7, 1, 0, 0, 1))
        model.stop_oscillator()
        clock.t = 100
        self.assertTrue(rtc.oscillator_stopped())
        self.assertEqual(rtc.datetime()[:6], (2025, 7, 1, 0, 0, 1))

    def test_temperature(self):
        clock, model, rtc = rtc_rig()
        for t in (25.75, -0.25, -12.5, 0.0, 85.0):
            model.temperature = t
            self.assertEqual(rtc.temperature(), t)

    def test_alarm1(self):
        clock, model, rtc = rtc_rig()
        rtc.set_datetime(2025, 1, 1, 12, 0, 0)
        rtc.set_alarm1(D.ALARM_MINUTES, second=30, minute=0)
        self.assertFalse(rtc.alarm1_fired())
        clock.t = 30
        self.assertTrue(rtc.alarm1_fired())
        rtc.clear_alarm1()
        clock.t = 31
        self.assertFalse(rtc.alarm1_fired())
        self.assertEqual(model.regs[0x0E] & 0x05, 0x05)


class TestSync(unittest.TestCase):
    def test_utc_frame_sets_rtc_at_the_next_whole_second(self):
        clock, model, rtc = rtc_rig()
        sync = D.TimeSync(rtc)
        day = days_from_civil(2025, 3, 1)
        self.assertTrue(sync.on_utc(UtcTime(day, 3600000 + 400), 10.0))
        self.assertAlmostEqual(sync.next_deadline(), 10.6)
        self.assertFalse(sync.poll(10.5))
        self.assertTrue(sync.poll(10.6))
        self.assertEqual(rtc.day_ms(), (day, 3601000))
        self.assertFalse(rtc.oscillator_stopped())
        clock.t = 2
        # in agreement now: no new set
        self.assertFalse(sync.on_utc(UtcTime(day, 3603000), 12.0))
        self.assertEqual(sync.last_error_ms, 0)
        sync.on_scet(ScetTime(5000), 12.0)
        self.assertEqual(sync.scet_offset, 5000 - (day * 86400 + 3603))
        self.assertEqual(sync.counters["sets"], 1)


class TestWatchdog(unittest.TestCase):
    def test_window_respected_with_jittery_loop(self):
        hal = ModelHal()
        wd = Watchdog(hal, open_ms=100, timeout_ms=1000)
        tps = Tps3813Model(100, 1000)
        wd.start(0)
        now = 0
        for i in range(5000):
            now += 1 + (i * 37) % 23  # loop period 1..23 ms
            before = hal.kick_count
            hal.now = now * 1000
            wd.poll(now)
            if hal.kick_count > before:
                self.assertIsNone(tps.kick(now))
            self.assertIsNone(tps.poll(now))
        self.assertEqual(tps.resets, 0)
        self.assertTrue(wd.kicks > 100)

    def test_unhealthy_is_reset_by_timeout(self):
        hal = ModelHal()
        wd = Watchdog(hal, open_ms=100, timeout_ms=1000)
        tps = Tps3813Model(100, 1000)
        wd.start(0)
        reason = None
        for now in range(0, 3000, 10):
            if wd.poll(now, healthy=now < 500):
                tps.kick(now)
            reason = reason or tps.poll(now)
        self.assertEqual(reason, "late")
        self.assertTrue(wd.withheld > 0)

    def test_early_kick_is_a_reset_in_the_model(self):
        tps = Tps3813Model(100, 1000)
        self.assertEqual(tps.kick(50), "early")
        with self.assertRaises(WatchdogConfigError):
            Watchdog(ModelHal(), open_ms=500, timeout_ms=510)

    def test_a_kick_seen_late_is_judged_by_its_own_spacing(self):
        # an observer that saw the last kick 250 ms late sees the next 60 ms after it: the
        # pulses were 300 ms apart, which the chip (beside the controller) sees
        tps = Tps3813Model(100, 1000)
        self.assertIsNone(tps.kick(550, gap_ms=None))
        self.assertIsNone(tps.kick(610, gap_ms=300))
        self.assertEqual(tps.kick(700, gap_ms=99), "early")
        self.assertEqual(tps.kick(800, gap_ms=100), None)
        self.assertEqual(tps.resets, 1)
