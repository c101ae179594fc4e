"""The reconfiguration application keeps its timing after years of uptime.

Its loop reads the time as seconds since boot, a float of the interpreter: in single precision
that float would be 1 s coarse after 97 days and 8 s after 2 years, so a 1 s report period
would collapse (``now + 1.0 == now``: a report every pass) and a 0.5 s heartbeat could not be
told from the next. The same application, SpaceCAN master and time are run for 20 s from boot
and from 3 years of uptime: it must send as many reports and heartbeats in both."""

import unittest

from obsw.reconfig.app import ReconfigApp
from obsw.reconfig.models import ModelHal
from obsw.reconfig.node import NODE_NOMINAL, definition
from obsw.spacecan.controller import Controller

YEARS_3_US = 3 * 365 * 86400 * 1000000
RUN_S = 20.0


def run(start_us):
    """(reports on the COM port, CAN frames sent, master's view of the node alive) over RUN_S."""
    hal = ModelHal(tick_us=200, eeprom_size=4096)
    hal.now = start_us
    app = ReconfigApp(hal)
    ctrl = Controller(heartbeat_period=0.5)
    ctrl.add_node(NODE_NOMINAL, definition(NODE_NOMINAL))
    ctrl.start(hal.now / 1000000)
    end = start_us + int(RUN_S * 1000000)
    reports = frames = 0
    while hal.now < end:
        for bus, can_id, data in ctrl.take_frames():
            hal.can_rx[bus].append((can_id, data))
        hal.idle(app.step())
        now = hal.now / 1000000
        frames += len(hal.can_tx)
        for bus, can_id, data in hal.can_tx:
            ctrl.receive(bus, can_id, data, now)
        hal.can_tx = []
        ctrl.poll(now)
        if hal.uart_tx[0]:
            reports += 1
            hal.uart_tx[0] = bytearray()
    return reports, frames


class TestUptime(unittest.TestCase):
    def test_three_years_up_keeps_the_periods_of_the_first_seconds(self):
        at_boot = run(0)
        later = run(YEARS_3_US)
        self.assertTrue(at_boot[0] > 10, at_boot)  # about one report a second
        self.assertTrue(at_boot[1] > 30, at_boot)  # heartbeats and answers, both buses
        for first, then in zip(at_boot, later):
            self.assertTrue(abs(first - then) <= 2, (at_boot, later))

    def test_the_interpreter_float_resolves_a_microsecond_after_years(self):
        # what the loop computes: microseconds since boot over a million
        now = (YEARS_3_US + 1) / 1000000
        self.assertNotEqual(now, YEARS_3_US / 1000000)
        self.assertNotEqual(now + 0.5, now)


if __name__ == "__main__":
    unittest.main()
