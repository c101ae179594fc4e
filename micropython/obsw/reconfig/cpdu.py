"""CPDU access: the thesis's modified Dekker arbitration between the two controllers.

Both controllers drive the same 12 D lines and one clock into two octal D flip-flops (the
nominal directly, the redundant through resistors). Each has a request line (CPDU_REQ) the other
reads. To write, a controller (1) waits until the other's request is low, (2) raises its own and
lets it settle, (3) enters if the other's is still low, else (4) waits a time that grows with
priority and (5) enters if the other's has dropped meanwhile, else lowers its own and retries.
The higher priority waits longer, so the lower one looks first, sees the conflict and backs off;
the nominal controller's base priority is higher, so it wins ties.

Mutual exclusion rests only on "raise own, then see the other low" (whatever the timing, as long
as the settle time covers the lines' rise time); the waits only decide who wins. A request line
stuck high is the hardware's business: an RC and Schmitt trigger reset that controller, whose pin
goes high-impedance, and the other carries on.

`Cpdu.step(now)` does at most one line access, so a simulator can interleave two controllers.
"""

from obsw.compat import const
from obsw.reconfig.hal import CPDU_MASK, NOMINAL

IDLE = const(0)
WAIT_OTHER = const(1)  # 1: wait for the other's request to drop
RAISE = const(2)  # 2: raise own request
SETTLE = const(3)  # 2: let it settle
CHECK = const(4)  # 3: other still low?
BATTLE = const(5)  # 4: priority-dependent wait
RECHECK = const(6)  # 5: other dropped?
LOWER = const(7)  # lost: drop own request and retry
INSIDE = const(8)  # granted: read back the latched state
DATA = const(9)  # drive the D lines
SETUP = const(10)  # data setup time before the clock edge
CLOCK_HIGH = const(11)  # rising edge latches
CLOCK_LOW = const(12)
RELEASE = const(13)  # lines to high impedance
DROP = const(14)  # own request low: done

STATE_NAMES = (
    "idle",
    "wait_other",
    "raise",
    "settle",
    "check",
    "battle",
    "recheck",
    "lower",
    "inside",
    "data",
    "setup",
    "clock_high",
    "clock_low",
    "release",
    "drop",
)


class CpduBusyError(RuntimeError):
    """A write was requested while the previous one is still in progress."""

    def __init__(self, state):
        super().__init__("CPDU write in progress (state %s)" % STATE_NAMES[state])
        self.state = state


class Cpdu:
    """One controller's side of the CPDU; ``hal`` gives the lines (see obsw.reconfig.hal).

    Times are microseconds. ``settle_us`` must cover the request line's rise time,
    ``setup_us`` the D lines' (longer for the redundant controller, which drives through
    resistors). ``battle_us`` is the priority step of the battle wait.
    """

    def __init__(self, hal, role=NOMINAL, settle_us=50, battle_us=100, setup_us=None, clock_us=10):
        self.hal = hal
        self.role = role
        self.settle_us = settle_us
        self.battle_us = battle_us
        self.setup_us = setup_us if setup_us is not None else (10 if role == NOMINAL else 40)
        self.clock_us = clock_us
        self.state = IDLE
        self.bits = 0  # what this controller believes is latched
        self.counters = {
            "writes": 0,
            "battles_won": 0,
            "battles_lost": 0,
            "waits": 0,
            "aborted": 0,
            "skipped": 0,
        }
        self.last_result = None  # the bits latched by the last write
        self.skipped = False  # the last write found its expectation unmet and drove nothing
        self._expect = None
        self._mask = 0
        self._value = 0
        self._priority = 0
        self._t = 0
        self._wait = 0
        self._new = 0

    @property
    def inside(self):
        """True from the grant until the own request line drops (the critical section)."""
        return INSIDE <= self.state <= DROP

    @property
    def busy(self):
        return self.state != IDLE

    def battle_wait(self, priority):
        """The battle wait for a priority: higher waits longer (and so wins)."""
        return self.battle_us * (2 * priority + (2 if self.role == NOMINAL else 1))

    def write(self, mask, value, priority=0, expect=None):
        """Start setting the lines in ``mask`` to ``value`` (others keep their state).

        ``expect`` = (mask, value): a compare-and-set; inside the critical section the latched
        lines are read back and, when they differ from ``expect``, nothing is driven and the
        write ends with ``skipped`` True (the other controller has made the change already).
        """
        if self.state != IDLE:
            raise CpduBusyError(self.state)
        self._mask = mask & CPDU_MASK
        self._value = value & CPDU_MASK
        self._priority = priority
        self._expect = expect
        self.skipped = False
        self.state = WAIT_OTHER

    def reset(self):
        """What a controller reset does: request line and outputs to high impedance."""
        if self.state != IDLE:
            self.counters["aborted"] += 1
        self.state = IDLE
        self.hal.req(0)
        self.hal.cpdu_release()

    def next_deadline(self):
        """When the current wait ends (microseconds), or None if not waiting on time."""
        if self.state in (SETTLE, BATTLE, SETUP, CLOCK_HIGH):
            return self._t + self._wait
        return None

    def step(self, now):
        """Advance by at most one line access; returns True when a write just finished."""
        s = self.state
        hal = self.hal
        if s == IDLE:
            return False
        if s == WAIT_OTHER:
            if hal.other_req():
                self.counters["waits"] += 1
            else:
                self.state = RAISE
        elif s == RAISE:
            hal.req(1)
            self._begin(SETTLE, now, self.settle_us)
        elif s in (SETTLE, BATTLE, SETUP, CLOCK_HIGH):
            if now - self._t < self._wait:
                return False
            if s == SETTLE:
                self.state = CHECK
            elif s == BATTLE:
                self.state = RECHECK
            elif s == SETUP:
                hal.cpdu_clock(1)
                self._begin(CLOCK_HIGH, now, self.clock_us)
            else:
                hal.cpdu_clock(0)
                self.state = RELEASE
        elif s == CHECK:
            if hal.other_req():
                self._begin(BATTLE, now, self.battle_wait(self._priority))
            else:
                self.state = INSIDE
        elif s == RECHECK:
            if hal.other_req():
                self.counters["battles_lost"] += 1
                self.state = LOWER
            else:
                self.counters["battles_won"] += 1
                self.state = INSIDE
        elif s == LOWER:
            hal.req(0)
            self.state = WAIT_OTHER
        elif s == INSIDE:
            latched = hal.cpdu_readback()
            if latched is not None:
                self.bits = latched
            e = self._expect
            if e is not None and latched is not None and latched & e[0] != e[1] & e[0]:
                self.skipped = True
                self.counters["skipped"] += 1
                self.state = DROP
                return False
            self._new = (self.bits & ~self._mask) | (self._value & self._mask)
            self.state = DATA
        elif s == DATA:
            hal.cpdu_data(self._new)
            self._begin(SETUP, now, self.setup_us)
        elif s == RELEASE:
            hal.cpdu_release()
            self.bits = self._new
            self.state = DROP
        elif s == DROP:
            hal.req(0)
            self.state = IDLE
            if not self.skipped:
                self.counters["writes"] += 1
                self.last_result = self.bits
            return True
        return False

    def _begin(self, state, now, wait):
        self.state = state
        self._t = now
        self._wait = wait

    def run(self, mask, value, clock, budget_us=20000, priority=0, expect=None):
        """Do a whole write now, stepping on ``clock()`` until done or ``budget_us`` passes.

        Returns True when latched; on running out of time the attempt is abandoned cleanly
        (own request dropped) and False is returned.
        """
        if self.state != IDLE:
            return False
        self.write(mask, value, priority, expect)
        start = clock()
        while True:
            now = clock()
            if self.step(now):
                return True
            if now - start > budget_us and not self.inside:
                self.reset()
                return False
