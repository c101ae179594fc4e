"""The reconfiguration module simulated with real processes: two MicroPython controllers, the
CPython OBC, the ground. Readiness is polled with deadlines; nothing asserts on timing."""

import json
import os

import pytest
from obsw.reconfig.essential import HPC_POWER_CYCLE, Hpc
from obsw.reconfig.hal import NOMINAL, REDUNDANT
from obsw.reconfig.node import definition_dict
from obsw_host.mission.new import TEMPLATE_DIR
from obsw_host.sample import CPDU_NODE_PATH
from obsw_sim import reconfig_hal as W
from obsw_sim.reconfig import ReconfigSim, micropython_binary

pytestmark = pytest.mark.skipif(
    micropython_binary() is None or not hasattr(os, "openpty"),
    reason="needs the MicroPython unix port and pseudo-terminals",
)

HERE = os.path.dirname(os.path.abspath(__file__))


def test_node_definition_shared_with_the_obc():
    for path in (CPDU_NODE_PATH, os.path.join(TEMPLATE_DIR, "nodes", "cpdu.json")):
        with open(path) as f:
            assert json.load(f) == definition_dict()


def log_of(sim):
    return "\n".join("%6.2f %s" % e for e in sim.events)


def test_arbitration_and_hpc_power_cycles_a_dead_obc(tmp_path):
    sim = ReconfigSim(str(tmp_path), obc_calls=["10:1:0x0F1", "11:2:0x100"])
    with sim:
        assert sim.wait_for(lambda: sim.seen("[N] ready") and sim.seen("[R] ready"))
        assert sim.wait_for(lambda: sim.seen("call 11:2:0x100 ->")), log_of(sim)
        assert sim.seen("call 10:1:0x0F1 -> completed"), log_of(sim)
        assert sim.seen("call 11:2:0x100 -> completed"), log_of(sim)
        # set_state_bits on CpduN writes all 12 lines, set_bits on CpduR only line 8: which
        # came last decides line 8; both were latched, one after the other
        lines = sim.lines()
        assert lines in (0x0F1, 0x1F1)
        w = sim.wire()
        assert w[W.LATCHES] == 2
        assert w[W.COLLISIONS] == 0
        first = sim.obc.popen.pid
        sim.kill_obc()
        assert not sim.obc.alive()
        sim.send_hpc(Hpc(HPC_POWER_CYCLE, (0, 200)))
        assert sim.wait_for(lambda: sim.obc_boots == 2 and sim.obc.alive())
        assert sim.obc.popen.pid != first
        assert sim.seen("supervisor: OBC power line off")
        assert sim.wait_for(lambda: sim.seen("[OBC] time sent"))

        def hptm():
            return [
                r for r in sim.reports[NOMINAL] if r.last_hpc == HPC_POWER_CYCLE and r.cpdu & 1
            ]

        reps = sim.wait_for(hptm)
        assert reps and reps[-1].hpcs == 1 and reps[-1].role == NOMINAL
        # the redundant controller saw the HPC too but left it to the nominal
        assert not [r for r in sim.reports[REDUNDANT] if r.hpcs]
        assert sim.lines() == lines


def test_stuck_request_line_resets_that_controller_only(tmp_path):
    sim = ReconfigSim(str(tmp_path))
    with sim:
        assert sim.wait_for(lambda: sim.seen("[N] ready") and sim.seen("[R] ready"))
        sim.stick_req(NOMINAL)
        assert sim.wait_for(lambda: sim.seen("[N] boot 2 (stuck reset)"))
        assert sim.resets[NOMINAL] == ["stuck"]
        assert sim.resets[REDUNDANT] == []
        # the redundant carries on: it takes over HPCs while the nominal is silent, and
        # after the reset the nominal serves again
        sim.send_hpc(Hpc(HPC_POWER_CYCLE, (3, 50)))
        assert sim.wait_for(lambda: sim.seen("cpdu 0x009 (mask 0x008)"))
