"""Aurora-1's attitude controller: a time-driven plug-in that detumbles the spacecraft.

Its periodic hook, ``tick(now)``, runs every ``period`` seconds (``mission.json``:
``"period": 0.2``) on the thread that serves the component: it integrates the body rate
under the B-dot law while the mode is DETUMBLE, publishes it, and when the rate is below the
threshold switches to POINTING by itself. ``select_mode`` takes the mode as a number or by its
label; the database labels the function argument and the event fields, so the ground writes
``mode=POINTING`` and reads ``new=POINTING``.
"""

import math

from obsw.il.interface import (
    CONFIGURATION,
    DATA,
    INFO,
    Attribute,
    Event,
    Interface,
    Operation,
)

ATTITUDE = Interface(
    "Attitude",
    0x62,
    [
        Attribute("rate", 1, DATA, type="f32", unit="deg/s", description="body rate norm"),
        Attribute(
            "mode", 2, CONFIGURATION, type="u8", description="0 OFF, 1 DETUMBLE, 2 POINTING"
        ),
        Attribute("gain", 3, CONFIGURATION, type="f32", unit="1/s", description="B-dot gain"),
        Attribute("ticks", 4, DATA, type="u32", description="control cycles run"),
        Operation("select_mode", 10, ("mode",), description="OFF, DETUMBLE or POINTING"),
        Operation("spin_up", 11, ("rate",), description="simulate a tumble (deg/s)"),
        Event("mode_changed", 20, INFO, fields=("old", "new")),
        Event("detumbled", 21, INFO, fields=("rate",)),
    ],
    description="B-dot detumbling controller (simulated dynamics)",
)

MODES = ("OFF", "DETUMBLE", "POINTING")
OFF, DETUMBLE, POINTING = 0, 1, 2


class Attitude:
    """The controller; ``threshold`` (deg/s) ends detumbling."""

    def __init__(self, rate=12.0, gain=0.5, threshold=0.5):
        self.rate = float(rate)
        self._gain = float(gain)
        self.threshold = float(threshold)
        self.mode = OFF
        self.ticks = 0
        self._last = None
        self.il = None

    def il_bind(self, provider):
        self.il = provider

    @property
    def gain(self):
        return self._gain

    @gain.setter
    def gain(self, value):
        if not 0 < value <= 5:
            raise ValueError("gain must be in (0, 5] 1/s", value)
        self._gain = float(value)

    def select_mode(self, mode):
        new = MODES.index(mode) if isinstance(mode, str) else int(mode)
        if new not in (OFF, DETUMBLE, POINTING):
            raise ValueError("mode must be OFF, DETUMBLE or POINTING", mode)
        self._switch(new)
        return new

    def spin_up(self, rate):
        self.il.update("rate", float(rate))
        return self.rate

    def _switch(self, new):
        old, self.mode = self.mode, new
        self.il.update("mode", new)
        if old != new:
            self.il.emit("mode_changed", {"old": old, "new": new})

    def tick(self, now):
        """One control cycle: ``now`` is time.monotonic(), on the component's own thread."""
        dt = 0.0 if self._last is None else now - self._last
        self._last = now
        self.il.update("ticks", self.ticks + 1)
        if self.mode != DETUMBLE:
            return
        self.il.update("rate", self.rate * math.exp(-self._gain * dt))
        if self.rate < self.threshold:
            self.il.emit("detumbled", {"rate": self.rate})
            self._switch(POINTING)
