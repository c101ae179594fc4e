"""TPS3813 window watchdog: kicked from the main loop, only while the application is healthy.

The TPS3813 resets the controller when WDI pulses come too early (inside the closed window) or
not at all before the timeout. `Watchdog.poll(now_ms, healthy)` pulses WDI once the window is
open, aiming at ``aim`` of the way through it, and never early; an unhealthy application
simply stops kicking and is reset by the hardware.
"""


class WatchdogConfigError(ValueError):
    """A window that leaves no time to kick in."""

    def __init__(self, msg):
        super().__init__(msg)


class Watchdog:
    """Times in milliseconds: ``open_ms`` closed window after a kick, ``timeout_ms`` limit."""

    def __init__(self, hal, open_ms=100, timeout_ms=1000, aim=0.25, margin_ms=10):
        if not 0 <= open_ms + margin_ms < timeout_ms - margin_ms:
            raise WatchdogConfigError(
                "watchdog window %d..%d ms leaves no room for a %d ms margin"
                % (open_ms, timeout_ms, margin_ms)
            )
        self.hal = hal
        self.open_ms = open_ms
        self.timeout_ms = timeout_ms
        self.margin_ms = margin_ms
        self.target_ms = open_ms + margin_ms + int((timeout_ms - open_ms - 2 * margin_ms) * aim)
        self.last = None
        self.kicks = 0
        self.withheld = 0
        self.late = 0

    def start(self, now_ms):
        """Take the reset (or the first kick) as the window's start."""
        self.last = now_ms

    def due(self, now_ms):
        return self.last is None or now_ms - self.last >= self.target_ms

    def next_deadline(self):
        return None if self.last is None else self.last + self.target_ms

    def poll(self, now_ms, healthy=True):
        """Kick if due and healthy; returns True when WDI was pulsed."""
        if self.last is not None:
            since = now_ms - self.last
            if since < self.target_ms:
                return False
            if since > self.timeout_ms:
                self.late += 1
        if not healthy:
            self.withheld += 1
            return False
        self.hal.wdi(1)
        self.hal.wdi(0)
        self.last = now_ms
        self.kicks += 1
        return True
