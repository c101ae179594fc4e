"""The simulated module recovers the OBC by itself: a hung OBC (SIGSTOP) and a killed one are
power-cycled without any ground TC and come back with their context and the DS3231's time;
after ``max_failures`` recoveries in the window the redundant OBC is switched on instead."""

import os
import time

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
        time.sleep(1.5)  # a few saves with the DS3231 set by the OBC's UTC

        sim.hang_obc()
        assert sim.wait_for(lambda: sim.seen("recovery: power_cycle line 0"), 20)
        assert sim.wait_for(lambda: sim.obc_boots == 2 and restored(sim, 2), 20)
        assert sim.seen("[OBC] onboard time from the DS3231")
        assert "seq={256:" in restored(sim, 2) and "boots=1" in restored(sim, 2)

        time.sleep(1.5)
        sim.kill_obc()
        assert sim.wait_for(lambda: sim.obc_boots == 3 and restored(sim, 3), 20)
        assert "boots=2" in restored(sim, 3)

        time.sleep(1.5)
        sim.kill_obc()
        assert sim.wait_for(lambda: sim.seen("recovery: switch_over line 0"), 20)
        assert sim.wait_for(lambda: sim.seen("[OBC] up on line 1"), 20)
        assert sim.wait_for(lambda: sim.obc_boots == 4 and restored(sim, 4), 20)
        assert "boots=3" in restored(sim, 4)  # the redundant OBC carries on the context
        assert sim.lines() & 0x003 == 0x002
        time.sleep(FAST["boot_grace"] + 1.0)  # the redundant OBC's heartbeats keep it on
        assert sim.lines() & 0x003 == 0x002
        acts = [e for _, e in sim.events if "recovery:" in e and "stood_down" not in e]
        assert len(acts) == 3, acts  # each fault acted on once, by one controller
        sim.wait_for(lambda: any(r.version for r in sim.reports[0]), 5)
