"""SpaceCAN redundancy: heartbeat deadlines, bus health on both buses, and failover rules."""

from obsw.spacecan.ids import BUS_A, other_bus


class ConfigError(ValueError):
    """A SpaceCAN configuration value of the wrong kind or out of range."""

    def __init__(self, key, expected, value):
        super().__init__("%s must be %s, got %r" % (key, expected, value))
        self.key = key
        self.value = value


def check_period(key, value, allow_off=True):
    if value is None and allow_off:
        return 0
    if not isinstance(value, (int, float)) or isinstance(value, bool) or value < 0:
        raise ConfigError(key, "a number of seconds >= 0", value)
    return value


def check_max_switches(value):
    """spacecan's max_bus_switch: False (or None) = unbounded, else an int >= 0."""
    if value is None or value is False:
        return None
    if not isinstance(value, int) or isinstance(value, bool) or value < 0:
        raise ConfigError("max_bus_switch", "false or an integer >= 0", value)
    return value


class BusHealth:
    """Traffic and errors seen on one bus; `state(now, window)` says ok / silent / error."""

    def __init__(self, bus):
        self.bus = bus
        self.rx_frames = 0
        self.tx_frames = 0
        self.tx_errors = 0
        self.bad_frames = 0
        self.heartbeats = 0
        self.last_rx = None
        self.last_heartbeat = None
        self.last_tx_error = None
        self.errors_since_rx = 0

    def received(self, now):
        self.rx_frames += 1
        self.last_rx = now
        self.errors_since_rx = 0

    def sent(self):
        self.tx_frames += 1

    def tx_failed(self, now):
        self.tx_errors += 1
        self.errors_since_rx += 1
        self.last_tx_error = now

    def state(self, now, window):
        if self.errors_since_rx:
            return "error"
        if self.last_rx is not None and now - self.last_rx <= window:
            return "ok"
        return "silent"

    def report(self, now, window, active):
        return {
            "bus": self.bus,
            "active": active,
            "state": self.state(now, window),
            "rx_frames": self.rx_frames,
            "tx_frames": self.tx_frames,
            "tx_errors": self.tx_errors,
            "bad_frames": self.bad_frames,
            "heartbeats": self.heartbeats,
            "silent_for": None if self.last_rx is None else now - self.last_rx,
        }


class HeartbeatMonitor:
    """A responder's view of the controller's heartbeat, by deadline rather than counted ticks.

    The active bus fails over when no heartbeat came on it for (max_miss + 1) periods, as in
    spacecan. Since both buses are received, a heartbeat on the standby bus after the active one
    missed more than half a period more is followed at once (`follow`), and when the deadline
    passes with heartbeats present on the other bus the switch goes there, not blindly.
    `max_switches` bounds switching without any heartbeat (None = unbounded). The period and
    max_miss are settings of the construction: the window they give is computed once.
    """

    def __init__(self, period=0.5, max_miss=3, max_switches=None, follow=True, bus=BUS_A):
        self.period = check_period("heartbeat_period", period)
        if not isinstance(max_miss, int) or isinstance(max_miss, bool) or max_miss < 0:
            raise ConfigError("max_miss_heartbeat", "an integer >= 0", max_miss)
        self.max_miss = max_miss
        self.window_s = (max_miss + 1) * self.period  # seconds without a heartbeat
        self.max_switches = check_max_switches(max_switches)
        self.follow = follow
        self.active = bus
        self.last = [None, None]
        self.deadline = None
        self.switches_without_heartbeat = 0
        self.switch_count = 0

    def window(self):
        return self.window_s

    def start(self, now):
        if self.period:
            self.deadline = now + self.window()

    def heartbeat(self, bus, now):
        """Note a heartbeat; return the reason string if the active bus changed, else None."""
        self.last[bus] = now
        self.switches_without_heartbeat = 0
        if bus == self.active:
            if self.period:
                self.deadline = now + self.window()
            return None
        last_active = self.last[self.active]
        if self.follow and (last_active is None or now - last_active > 1.5 * self.period):
            self._switch(bus, now)
            return "heartbeat on bus %s" % "AB"[bus]
        return None

    def _switch(self, bus, now):
        self.active = bus
        self.switch_count += 1
        if self.period:
            self.deadline = now + self.window()

    def poll(self, now):
        """Fail over if the deadline passed; return the reason string if the bus changed."""
        if self.deadline is None or now < self.deadline:
            return None
        if self.max_switches is not None and self.switches_without_heartbeat >= self.max_switches:
            self.deadline = None  # stay put until a heartbeat comes
            return None
        self.switches_without_heartbeat += 1
        self._switch(other_bus(self.active), now)
        return "no heartbeat for %.3f s" % self.window()

    def next_deadline(self):
        return self.deadline
