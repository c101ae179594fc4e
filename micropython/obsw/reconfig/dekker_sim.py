"""A deterministic simulator of the two controllers sharing the CPDU lines (tests, soak, bench).

Each scheduling step picks one controller at random (seeded), advances the simulated clock by a
random amount and lets that controller do one line access. The lines are modelled as wired on
the board: request lines rise with a delay, the nominal controller's outputs win over the
redundant's (resistor coupling), the flip-flops latch the resolved D lines on a rising edge of
the resolved clock, and a request line high for longer than ``stuck_us`` resets its controller.
Not frozen into the board image.
"""

from obsw.reconfig.cpdu import Cpdu
from obsw.reconfig.hal import CPDU_MASK, NOMINAL, REDUNDANT


class Rng:
    """xorshift32: the same sequence on every interpreter."""

    def __init__(self, seed=1):
        self.s = (seed & 0xFFFFFFFF) or 0x9E3779B9

    def next(self):
        x = self.s
        x ^= (x << 13) & 0xFFFFFFFF
        x ^= x >> 17
        x ^= (x << 5) & 0xFFFFFFFF
        self.s = x
        return x

    def below(self, n):
        return self.next() % n


class _Port:
    """One controller's pins on the shared lines."""

    def __init__(self, sim, index):
        self.sim = sim
        self.i = index

    def req(self, level):
        self.sim.set_req(self.i, level)

    def other_req(self):
        return self.sim.visible_req(1 - self.i)

    def cpdu_data(self, bits):
        self.sim.drive_data[self.i] = bits & CPDU_MASK

    def cpdu_clock(self, level):
        self.sim.set_clock(self.i, level)

    def cpdu_release(self):
        self.sim.drive_data[self.i] = None
        self.sim.set_clock(self.i, None)

    def cpdu_readback(self):
        return self.sim.q if self.sim.readback else None


class DekkerSim:
    """Two Cpdu state machines on simulated lines; ``run(steps)`` and the counters tell."""

    def __init__(
        self,
        seed=1,
        rise_us=20,
        settle_us=50,
        battle_us=100,
        max_dt=40,
        stuck_us=20000,
        reset_us=5000,
        start_rate=8,
        readback=True,
    ):
        self.rng = Rng(seed)
        self.now = 0
        self.rise_us = rise_us
        self.max_dt = max_dt
        self.stuck_us = stuck_us
        self.reset_us = reset_us
        self.start_rate = start_rate  # 1 in start_rate idle steps starts a new write
        self.readback = readback
        self.q = 0
        self.drive_data = [None, None]
        self.drive_clock = [None, None]
        self._req = [[0, 0, -(10**9)], [0, 0, -(10**9)]]  # level, previous level, changed at
        self._req_high_since = [None, None]
        self._clock_level = 0
        self.hung = [False, False]
        self.stuck = [False, False]
        self.in_reset_until = [None, None]
        self.ctrl = [
            Cpdu(_Port(self, 0), NOMINAL, settle_us, battle_us),
            Cpdu(_Port(self, 1), REDUNDANT, settle_us, battle_us),
        ]
        self.intent = [None, None]
        self.counters = {
            "steps": 0,
            "both_inside": 0,
            "latches": 0,
            "wrong_latch": 0,
            "collisions": 0,
            "done0": 0,
            "done1": 0,
            "resets0": 0,
            "resets1": 0,
        }

    # -- the lines ----------------------------------------------------------------------------

    def set_req(self, i, level):
        r = self._req[i]
        level = 1 if (level or self.stuck[i]) else 0
        if level != r[0]:
            r[1] = self.visible_req(i)
            r[0] = level
            r[2] = self.now
            self._req_high_since[i] = self.now if level else None

    def visible_req(self, i):
        r = self._req[i]
        return r[0] if self.now - r[2] >= self.rise_us else r[1]

    def _resolved(self, pair):
        return pair[NOMINAL] if pair[NOMINAL] is not None else pair[REDUNDANT]

    def set_clock(self, i, level):
        self.drive_clock[i] = level
        c = self._resolved(self.drive_clock) or 0
        if c and not self._clock_level:
            self._latch(i)
        self._clock_level = c

    def _latch(self, i):
        self.counters["latches"] += 1
        if self.drive_data[0] is not None and self.drive_data[1] is not None:
            self.counters["collisions"] += 1
        d = self._resolved(self.drive_data)
        self.q = d if d is not None else 0
        if self.q != self.ctrl[i]._new:
            self.counters["wrong_latch"] += 1

    # -- faults -------------------------------------------------------------------------------

    def hang(self, i):
        """Controller i stops running where it is (its lines stay as they are)."""
        self.hung[i] = True

    def stick(self, i):
        """Controller i's request line is driven high and the controller hangs."""
        self.stuck[i] = True
        self.hung[i] = True
        self.set_req(i, 1)

    def _reset(self, i):
        self.counters["resets%d" % i] += 1
        self.stuck[i] = False
        self.hung[i] = False
        self.ctrl[i].reset()
        self.intent[i] = None
        self.in_reset_until[i] = self.now + self.reset_us

    # -- scheduling ---------------------------------------------------------------------------

    def step(self):
        rng = self.rng
        self.now += rng.below(self.max_dt + 1)
        self.counters["steps"] += 1
        for j in (0, 1):
            since = self._req_high_since[j]
            if since is not None and self.now - since >= self.stuck_us:
                self._reset(j)
        i = rng.next() & 1
        until = self.in_reset_until[i]
        if until is not None:
            if self.now < until:
                return
            self.in_reset_until[i] = None
        if self.hung[i]:
            return
        c = self.ctrl[i]
        if not c.busy:
            if rng.below(self.start_rate) == 0:
                mask = rng.below(CPDU_MASK + 1)
                c.write(mask, rng.below(CPDU_MASK + 1), rng.below(2))
            return
        if c.step(self.now):
            self.counters["done%d" % i] += 1
        if self.ctrl[0].inside and self.ctrl[1].inside:
            self.counters["both_inside"] += 1

    def run(self, steps):
        for _ in range(steps):
            self.step()
        return self.counters
