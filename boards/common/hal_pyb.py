"""The reconfiguration module's hardware layer on a Pyboard v1.1 (pyb / machine).

Pins (board OBSW_RECONFIG, see its pins.csv): CPDU D0-D11 on X3-X8, X11, X12, X19, X20, X9, X10;
CPDU clock X21; own CPDU_REQ X22, the other's Y7; alive out Y8, the other's X18; TPS3813 WDI Y11;
role strap Y12 (open: nominal, grounded: redundant); I2C(2) on Y9/Y10 with the M24512s at 0x50
and 0x51 and the DS3231 at 0x68; CAN(1) Y3/Y4 bus A, CAN(2) Y5/Y6 bus B; UART(4) X1/X2 to the
COM module, UART(6) Y1/Y2 to the OBC. Nothing is touched until PybHal() is created.
"""

import time

import machine
import pyb
from obsw.reconfig.hal import (
    NOMINAL,
    REDUNDANT,
    RESET_POWER,
    RESET_SOFT,
    RESET_WATCHDOG,
    Hal,
)

D_PINS = ("CPDU_D0", "CPDU_D1", "CPDU_D2", "CPDU_D3", "CPDU_D4", "CPDU_D5")
D_PINS += ("CPDU_D6", "CPDU_D7", "CPDU_D8", "CPDU_D9", "CPDU_D10", "CPDU_D11")


class PybHal(Hal):
    """Pyboard pins, I2C(2), CAN(1)/CAN(2) at 1 Mbit/s, UART(4)/UART(6)."""

    def __init__(self, baudrate=115200, can_baudrate=1000000, i2c_freq=400000):
        Pin = machine.Pin
        self._in = Pin.IN
        self._role = Pin("CPDU_ROLE", Pin.IN, Pin.PULL_UP)
        self.role = NOMINAL if self._role.value() else REDUNDANT
        self._d = [Pin(n, Pin.IN) for n in D_PINS]
        self._clk = Pin("CPDU_CLK", Pin.IN)
        self._req = Pin("CPDU_REQ", Pin.OUT, value=0)
        self._req_other = Pin("CPDU_REQ_OTHER", Pin.IN, Pin.PULL_DOWN)
        self._alive = Pin("ALIVE", Pin.OUT, value=0)
        self._alive_other = Pin("ALIVE_OTHER", Pin.IN, Pin.PULL_DOWN)
        self._wdi = Pin("WDI", Pin.OUT, value=0)
        self.i2c = machine.I2C(2, freq=i2c_freq)
        self._cans = []
        for n in (1, 2):
            can = pyb.CAN(n)
            can.init(pyb.CAN.NORMAL, baudrate=can_baudrate, auto_restart=True)
            can.setfilter(0, pyb.CAN.MASK16, 0, (0, 0, 0, 0))
            self._cans.append(can)
        self._uarts = [
            machine.UART(4, baudrate, timeout=0, rxbuf=1024),
            machine.UART(6, baudrate, timeout=0, rxbuf=1024),
        ]
        self._cause = machine.reset_cause()
        self._last = time.ticks_us()
        self._acc = 0

    def now_us(self):
        t = time.ticks_us()
        self._acc += time.ticks_diff(t, self._last)
        self._last = t
        return self._acc

    def cpdu_data(self, bits):
        for i in range(12):
            p = self._d[i]
            p.init(p.OUT, value=(bits >> i) & 1)

    def cpdu_clock(self, level):
        self._clk.init(self._clk.OUT, value=level)

    def cpdu_release(self):
        for p in self._d:
            p.init(self._in)
        self._clk.init(self._in)

    def req(self, level):
        self._req.value(level)

    def other_req(self):
        return bool(self._req_other.value())

    def alive(self, level):
        self._alive.value(level)

    def other_alive(self):
        return self._alive_other.value()

    def wdi(self, level):
        self._wdi.value(level)

    def can_recv(self, bus):
        can = self._cans[bus]
        if not can.any(0):
            return None
        msg = can.recv(0, timeout=0)
        # (id, isext, rtr, fmi, data) on current firmware, (id, rtr, fmi, data) on older
        if len(msg) == 5 and (msg[1] or msg[2]):
            return None
        return msg[0], msg[-1]

    def can_send(self, bus, can_id, data):
        try:
            self._cans[bus].send(data, can_id, timeout=0)
            return True
        except OSError:  # mailboxes full or bus-off
            return False

    def uart_read(self, port):
        u = self._uarts[port]
        n = u.any()
        return u.read(n) if n else b""

    def uart_write(self, port, data):
        self._uarts[port].write(data)

    def reset_cause(self):
        c = self._cause
        if c == machine.PWRON_RESET:
            return RESET_POWER
        if c == machine.SOFT_RESET:
            return RESET_SOFT
        # NRST pulled low: the TPS3813 or the CPDU_REQ supervisor (not told apart by the MCU)
        return RESET_WATCHDOG

    def reset(self):
        machine.reset()

    def idle(self, ms):
        if ms > 0:
            time.sleep_ms(ms)
