"""The simulated module recovers the OBC by itself: a hung OBC (SIGSTOP) and a killed one are
power-cycled without any ground TC and come back with their context and the DS3231's time;
after ``max_failures`` recoveries in the window the redundant OBC is switched on instead."""

import os

import pytest
from obsw.reconfig.recovery import DEFAULTS
from obsw_host.mission.defaults import RECOVERY, section
from obsw_sim.reconfig import ReconfigSim, micropython_binary

pytestmark = pytest.mark.skipif(
    micropython_binary() is None or not hasattr(os, "openpty"),
    reason="needs the MicroPython unix port and pseudo-terminals",
)

FAST = {"deadline": 1.0, "boot_grace": 4.0, "off_ms": 200, "max_failures": 2, "window": 120.0}


def restored(sim, boot):
    """The context line printed by the OBC's ``boot``-th start (1-based), or None."""
    lines = [t for _, t in sim.events if "[OBC] context restored" in t]
    return lines[boot - 2] if len(lines) >= boot - 1 else None


def saves(sim, boot):
    """How many context saves the OBC's ``boot``-th start (1-based) logged so far."""
    n, count = 0, 0
    for _, text in sim.log_lines():
        if "[OBC] up on line" in text:
            n += 1
        elif n == boot and "[OBC] context saved" in text:
            count += 1
    return count


def rtc_set(sim):
    """True once both controllers set their DS3231 from the OBC's UTC and report its time."""
    sim.poll_tm()
    return sim.seen("RTC set from the OBC's UTC") and all(r and r[-1].utc_day for r in sim.reports)


def uptimes(sim):
    """Each controller's uptime in seconds, as its newest report gives it (None: none yet)."""
    sim.poll_tm()
    return [r[-1].uptime if r else None for r in sim.reports]


def test_defaults_in_one_place():
    assert RECOVERY["deadline"] == DEFAULTS["deadline"]

    class Config:
        def section(self, name):
            return {"deadline": 20.0}

    assert section(Config(), "recovery")["deadline"] == 20.0
    assert section(Config(), "recovery")["max_failures"] == DEFAULTS["max_failures"]


def test_hung_and_killed_obc_recovered_then_switched_over(tmp_path):
    sim = ReconfigSim(str(tmp_path), obc_lines=(0, 1), recovery=FAST)
    with sim:
        assert sim.wait_for(lambda: sim.seen("[OBC] context saved"), 30)
        assert sim.wait_for(lambda: rtc_set(sim), 20)  # the DS3231 set by the OBC's UTC
        done = saves(sim, 1)
        assert sim.wait_for(lambda: saves(sim, 1) >= done + 2, 20)  # saves after that

        sim.hang_obc()
        assert sim.wait_for(lambda: sim.seen("recovery: power_cycle line 0"), 20)
        assert sim.wait_for(lambda: sim.obc_boots == 2 and restored(sim, 2), 20)
        assert sim.seen("[OBC] onboard time from the DS3231")
        assert "seq={256:" in restored(sim, 2) and "boots=1" in restored(sim, 2)

        assert sim.wait_for(lambda: saves(sim, 2) >= 2, 20)  # the second start's context
        sim.kill_obc()
        assert sim.wait_for(lambda: sim.obc_boots == 3 and restored(sim, 3), 20)
        assert "boots=2" in restored(sim, 3)

        assert sim.wait_for(lambda: saves(sim, 3) >= 2, 20)  # the third start's context
        sim.kill_obc()
        assert sim.wait_for(lambda: sim.seen("recovery: switch_over line 0"), 20)
        assert sim.wait_for(lambda: sim.seen("[OBC] up on line 1"), 20)
        assert sim.wait_for(lambda: sim.obc_boots == 4 and restored(sim, 4), 20)
        assert "boots=3" in restored(sim, 4)  # the redundant OBC carries on the context
        assert sim.lines() & 0x003 == 0x002
        # the redundant OBC's heartbeats keep it on: the controllers' clocks pass the time
        # by which they would have acted on its silence (boot grace, then the deadline)
        quiet = FAST["boot_grace"] + FAST["deadline"] + 1
        since = uptimes(sim)
        assert None not in since
        assert sim.wait_for(lambda: all(u >= s + quiet for u, s in zip(uptimes(sim), since)), 30)
        assert sim.lines() & 0x003 == 0x002
        acts = [e for _, e in sim.events if "recovery:" in e and "stood_down" not in e]
        assert len(acts) == 3, acts  # each fault acted on once, by one controller
        sim.wait_for(lambda: any(r.version for r in sim.reports[0]), 5)
