"""Models of the module's parts for tests and the host simulation: I2C with fault injection,
M24512, DS3231, TPS3813, and an in-memory hardware layer. Not frozen into the board image."""

import json

from obsw.reconfig.dekker_sim import Rng
from obsw.reconfig.hal import CPDU_MASK, NOMINAL, RESET_POWER, Hal
from obsw.utc import civil_from_days, days_from_civil

_EIO = 5
_ENODEV = 19


class SimReset(Exception):
    """A controller reset injected in the middle of an I2C transfer."""

    def __init__(self, where):
        super().__init__("reset injected during %s" % where)
        self.where = where


class SimI2C:
    """A ``machine.I2C``-like bus with devices by address, bit errors and injected resets.

    ``bit_error_gap``: mean number of bits between flipped bits on the wire (0: none).
    ``reset_in``: number of transfers after which a SimReset is raised (None: never); a write
    hit by it leaves its page torn as the device model decides.
    """

    def __init__(self, seed=1, bit_error_gap=0):
        self.rng = Rng(seed)
        self.devices = {}
        self.bit_error_gap = bit_error_gap
        self.reset_in = None
        self.transfers = 0
        self.flipped = 0
        self._gap = self._draw()

    def _draw(self):
        g = self.bit_error_gap
        return 1 + self.rng.below(2 * g) if g else -1

    def _noise(self, buf):
        if self._gap < 0:
            return buf
        bits = len(buf) * 8
        if self._gap > bits:
            self._gap -= bits
            return buf
        out = bytearray(buf)
        pos = self._gap - 1
        while pos < bits:
            out[pos >> 3] ^= 0x80 >> (pos & 7)
            self.flipped += 1
            gap = self._draw()
            pos += gap
        self._gap = pos - bits + 1
        return out

    def _device(self, addr):
        dev = self.devices.get(addr)
        if dev is None:
            raise OSError(_ENODEV)
        return dev

    def _tick(self):
        self.transfers += 1
        if self.reset_in is not None:
            self.reset_in -= 1
            return self.reset_in < 0
        return False

    def readfrom_mem(self, addr, mem, n, addrsize=8):
        dev = self._device(addr)
        if self._tick():
            self.reset_in = None
            raise SimReset("read")
        return bytes(self._noise(dev.read(mem, n)))

    def writeto_mem(self, addr, mem, buf, addrsize=8):
        dev = self._device(addr)
        data = self._noise(bytes(buf))
        if self._tick():
            self.reset_in = None
            dev.torn_write(mem, data, self.rng)
            raise SimReset("write")
        dev.write(mem, data)

    def writeto(self, addr, buf):
        dev = self._device(addr)
        if dev.busy > 0:
            dev.busy -= 1
            raise OSError(_EIO)
        return 1


class M24512Model:
    """64 KiB in 128-byte pages; a page write wraps within its page; busy for a few polls.

    With ``path`` the contents persist in that file (the host simulation's EEPROM). ``size``
    (a power of two) models only the low part of the device, for a board's small heap.
    """

    def __init__(self, path=None, busy_polls=2, size=65536):
        self.path = path
        self.busy_polls = busy_polls
        self.busy = 0
        self.mask = size - 1
        self.mem = bytearray(b"\xff" * size)
        self._file = None
        if path is not None:
            try:
                f = open(path, "r+b")
                f.readinto(self.mem)
            except OSError:
                f = open(path, "w+b")
                f.write(self.mem)
            self._file = f

    def read(self, mem, n):
        out = bytearray(n)
        for i in range(n):
            out[i] = self.mem[(mem + i) & self.mask]
        return out

    def _put(self, mem, data, keep=None):
        page = mem & 0xFF80
        for i in range(len(data)):
            a = page | ((mem + i) & 0x7F)
            if keep is None or not keep(i):
                self.mem[a] = data[i]
        if self._file is not None:
            self._file.seek(page)
            self._file.write(self.mem[page : page + 128])
            if hasattr(self._file, "flush"):
                self._file.flush()

    def write(self, mem, data):
        self._put(mem, data)
        self.busy = self.busy_polls

    def torn_write(self, mem, data, rng):
        """Power lost during the write: nothing, everything, or an arbitrary mix with garbage."""
        mode = rng.below(4)
        if mode == 0:
            return
        if mode == 1:
            self._put(mem, data)
            return
        mixed = bytearray(data)
        for i in range(len(mixed)):
            r = rng.below(8)
            if r == 0:
                mixed[i] = rng.below(256)
            elif r < 4:
                mixed[i] = self.mem[(mem & 0xFF80) | ((mem + i) & 0x7F)]
        if mode == 2:
            cut = rng.below(len(data) + 1)  # the cells written in order, up to a point
            self._put(mem, data, lambda i: i >= cut)
        else:
            self._put(mem, mixed)


def _bcd(v):
    return ((v // 10) << 4) | (v % 10)


def _unbcd(b):
    return (b >> 4) * 10 + (b & 0x0F)


class DS3231Model:
    """The DS3231's registers over a running clock: ``clock()`` gives seconds (float).

    Time is held as UTC seconds since 1958-01-01 at the last set plus the elapsed clock.
    ``stop_oscillator()`` freezes it and raises OSF. ``temperature`` in degrees C (0.25 steps).
    """

    def __init__(self, clock, path=None, seconds=0):
        self.clock = clock
        self.path = path
        self.regs = bytearray(0x13)
        self.regs[0x0E] = 0x1C
        self.regs[0x0F] = 0x88  # OSF set at first power-up, EN32kHz
        self.running = True
        self.temperature = 21.25
        self.busy = 0
        self._base = seconds
        self._at = clock()
        if path is not None:
            try:
                with open(path) as f:
                    d = json.load(f)
                # the clock is the host's wall clock: the time runs on across a restart of
                # the controller as a DS3231 on its battery does (whole seconds, as it counts)
                self._base = int(d["base"])
                self._at = float(d["at"]) if d["running"] else clock()
                self.regs[0x07:0x13] = bytes(d["regs"])
                self.running = d["running"]
            except (OSError, ValueError, KeyError):
                self._save()

    def _save(self):
        if self.path is not None:
            with open(self.path, "w") as f:
                d = {"base": self._base, "at": self._at, "running": self.running}
                d["regs"] = list(self.regs[0x07:0x13])
                json.dump(d, f)

    def seconds(self):
        if not self.running:
            return self._base
        return self._base + int(self.clock() - self._at)

    def stop_oscillator(self):
        self._base = self.seconds()
        self.running = False
        self.regs[0x0F] |= 0x80
        self._save()

    def _time_regs(self):
        t = self.seconds()
        days = t // 86400
        rest = t - days * 86400
        y, mo, d = civil_from_days(days)
        out = bytearray(7)
        out[0] = _bcd(rest % 60)
        out[1] = _bcd((rest // 60) % 60)
        out[2] = _bcd(rest // 3600)
        out[3] = (days + 2) % 7 + 1
        out[4] = _bcd(d)
        out[5] = _bcd(mo) | (0x80 if y >= 2100 else 0)
        out[6] = _bcd(y % 100)
        return out

    def _alarm1(self, now_regs):
        a = self.regs[7:11]
        # A1M1..A1M4 mask bits: compare only the fields whose mask bit is 0
        for i in range(3):
            if not a[i] & 0x80 and (a[i] & 0x7F) != now_regs[i]:
                return False
        if not a[3] & 0x80:
            field = now_regs[3] if a[3] & 0x40 else now_regs[4]
            if (a[3] & 0x3F) != field:
                return False
        return True

    def read(self, mem, n):
        regs = bytearray(self.regs)
        t = self._time_regs()
        regs[0:7] = t
        if self._alarm1(t):
            self.regs[0x0F] |= 0x01
            regs[0x0F] = self.regs[0x0F]
        temp = int(self.temperature * 4)
        temp &= 0x3FF
        regs[0x11] = temp >> 2
        regs[0x12] = (temp & 3) << 6
        out = bytearray(n)
        for i in range(n):
            out[i] = regs[(mem + i) % 0x13]
        return out

    def write(self, mem, data):
        touched_time = False
        for i in range(len(data)):
            a = (mem + i) % 0x13
            if a < 7:
                touched_time = True
            elif a == 0x0F:
                # OSF, A2F, A1F can only be cleared; EN32kHz is writable
                self.regs[a] = (self.regs[a] & data[i] & 0x83) | (data[i] & 0x08)
            elif a < 0x11:
                self.regs[a] = data[i]
        if touched_time:
            t = bytearray(self._time_regs())
            for i in range(len(data)):
                a = (mem + i) % 0x13
                if a < 7:
                    t[a] = data[i]
            y = 2000 + _unbcd(t[6]) + (100 if t[5] & 0x80 else 0)
            days = days_from_civil(y, _unbcd(t[5] & 0x1F), _unbcd(t[4]))
            self._base = days * 86400 + _unbcd(t[2] & 0x3F) * 3600 + _unbcd(t[1]) * 60
            self._base += _unbcd(t[0] & 0x7F)
            self._at = self.clock()
            self.running = True
        self._save()

    def torn_write(self, mem, data, rng):
        pass


class Tps3813Model:
    """Window watchdog: a kick earlier than ``open_ms`` after the last, or none within
    ``timeout_ms``, asserts reset. ``kick(now_ms, gap_ms)`` and ``poll(now_ms)`` return
    "early", "late" or None. ``gap_ms``, when given, is the kick's distance from the one before
    as the pulses themselves were timed (the chip sits beside the controller): an observer that
    sees kicks some time after they happen passes it, so that its own delays never make a kick
    look early."""

    def __init__(self, open_ms, timeout_ms, now_ms=0):
        self.open_ms = open_ms
        self.timeout_ms = timeout_ms
        self.last = now_ms
        self.resets = 0

    def kick(self, now_ms, gap_ms=None):
        early = (now_ms - self.last if gap_ms is None else gap_ms) < self.open_ms
        self.last = now_ms
        if early:
            self.resets += 1
            return "early"
        return None

    def poll(self, now_ms):
        if now_ms - self.last > self.timeout_ms:
            self.resets += 1
            self.last = now_ms
            return "late"
        return None


class ModelHal(Hal):
    """An in-memory hardware layer on a manual clock (``now`` in microseconds; each reading
    of it moves it on by ``tick_us``, as time passes while code runs)."""

    def __init__(
        self, role=NOMINAL, seed=1, bit_error_gap=0, rtc_seconds=0, tick_us=5, eeprom_size=65536
    ):
        self.role = role
        self.now = 0
        self.tick_us = tick_us
        self.i2c = SimI2C(seed, bit_error_gap)
        self.eeproms = [M24512Model(size=eeprom_size), M24512Model(size=eeprom_size)]
        self.i2c.devices[0x50] = self.eeproms[0]
        self.i2c.devices[0x51] = self.eeproms[1]
        self.rtc = DS3231Model(lambda: self.now / 1000000, seconds=rtc_seconds)
        self.i2c.devices[0x68] = self.rtc
        self.q = 0
        self.data = None
        self.clock = 0
        self.own_req = 0
        self.other = 0
        self.alive_level = 0
        self.wdi_level = 0
        self.kicks = []  # the times (ms) of the last 64 WDI pulses
        self.kick_count = 0
        self.can_rx = [[], []]
        self.can_tx = []
        self.uart_rx = [bytearray(), bytearray()]
        self.uart_tx = [bytearray(), bytearray()]
        self.cause = RESET_POWER
        self.resets = 0

    def now_us(self):
        self.now += self.tick_us
        return self.now

    def cpdu_data(self, bits):
        self.data = bits & CPDU_MASK

    def cpdu_clock(self, level):
        if level and not self.clock and self.data is not None:
            self.q = self.data
        self.clock = level

    def cpdu_release(self):
        self.data = None
        self.clock = 0

    def cpdu_readback(self):
        return self.q

    def req(self, level):
        self.own_req = level

    def other_req(self):
        return bool(self.other)

    def alive(self, level):
        self.alive_level = level

    def wdi(self, level):
        if level and not self.wdi_level:
            self.kick_count += 1
            self.kicks.append(self.now // 1000)
            if len(self.kicks) > 64:
                self.kicks.pop(0)
        self.wdi_level = level

    def can_recv(self, bus):
        q = self.can_rx[bus]
        return q.pop(0) if q else None

    def can_send(self, bus, can_id, data):
        self.can_tx.append((bus, can_id, bytes(data)))
        return True

    def uart_read(self, port):
        b = self.uart_rx[port]
        if not b:
            return b""
        out = bytes(b)
        self.uart_rx[port] = bytearray()
        return out

    def uart_write(self, port, data):
        self.uart_tx[port].extend(data)

    def reset_cause(self):
        return self.cause

    def reset(self):
        self.resets += 1
        raise SimReset("soft reset")

    def idle(self, ms):
        self.now += ms * 1000
