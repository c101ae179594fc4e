"""The components' periodic hook (``obsw_host.obc.ticks``): ``tick(now)`` every ``period``
seconds on the unit's thread, in rhythm, never in a burst after a stall, a failure said."""

import pytest
from obsw_host.obc.plugins import Component, PluginError
from obsw_host.obc.ticks import IDLE, Ticks


class Clock:
    def __init__(self):
        self.now = 100.0

    def __call__(self):
        return self.now


class Counter:
    def __init__(self, fail=False):
        self.seen = []
        self.fail = fail

    def tick(self, now):
        self.seen.append(now)
        if self.fail:
            raise RuntimeError("sensor gone")


def ticking(impl, period, clock, out):
    c = Component("Counter", {"module": "x.py", "period": period})
    return Ticks([(c, (None, impl))], out, clock)


def test_ticks_keep_their_rhythm_and_skip_what_a_stall_missed():
    clock, impl = Clock(), Counter()
    t = ticking(impl, 0.25, clock, print)
    assert t.run_due() == pytest.approx(IDLE)  # ticked at once; the next one 0.25 away
    clock.now += 0.1
    assert t.run_due() == pytest.approx(0.15) and len(impl.seen) == 1
    clock.now += 0.16  # a little late: the one after keeps the phase
    t.run_due()
    assert len(impl.seen) == 2 and t.entries[0][3] == pytest.approx(100.5)
    clock.now += 3.0  # a stall of 12 periods: one tick, then on the old phase
    t.run_due()
    assert len(impl.seen) == 3
    assert t.entries[0][3] == pytest.approx(103.5)  # the first of the phase after now


def test_a_failing_tick_is_said_once_then_its_recovery():
    clock, impl, lines = Clock(), Counter(fail=True), []
    t = ticking(impl, 1.0, clock, lines.append)
    for _ in range(3):
        t.run_due()
        clock.now += 1.0
    impl.fail = False
    t.run_due()
    assert lines == ["component Counter: tick(now) failed: RuntimeError: sensor gone",
                     "component Counter: tick works again"]  # fmt: skip
    assert (t.failures, t.ticks) == (3, 1)


def test_no_period_no_ticks():
    t = Ticks([(Component("C", {"module": "x.py"}), (None, Counter()))], print, Clock())
    assert not t and t.run_due() == IDLE


@pytest.mark.parametrize("period", [0, -1, "fast", True])
def test_a_period_is_seconds_above_zero(period):
    with pytest.raises(PluginError) as e:
        Component("C", {"module": "x.py", "period": period})
    assert e.value.key == "components.C.period"
