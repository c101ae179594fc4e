"""The reconfiguration module simulated on the host, and its part of `obsw demo`.

``demo(out=print)``: both controllers start as MicroPython processes and the OBC boots; the OBC
commands set_state_bits on CpduN and set_bits on CpduR at the same moment (the controllers
arbitrate the CPDU); the OBC process is killed; a high priority command from the ground
power-cycles it through the CPDU; a controller with a stuck request line is reset.
"""

from obsw_sim.reconfig import ReconfigSim  # noqa: F401


def demo(out=print):
    from obsw.reconfig.essential import HPC_POWER_CYCLE, Hpc
    from obsw.reconfig.hal import NOMINAL, REDUNDANT

    out("reconfiguration module: two MicroPython controllers, the OBC, the ground")
    calls = ["10:1:0x0F1", "11:2:0x100"]  # CpduN set_state_bits 0x0F1, CpduR set_bits 0x100
    sim = ReconfigSim(obc_calls=calls, out=out)
    ok = True
    with sim:
        ok &= bool(sim.wait_for(lambda: sim.seen("[N] ready") and sim.seen("[R] ready"), 20))
        ok &= bool(sim.wait_for(lambda: sim.seen("call 11:2:0x100 ->"), 20))
        out("  CPDU lines now 0x%03X (wire: %d latches, %d collisions)" % _wire(sim))
        pid = sim.obc.popen.pid
        sim.kill_obc()
        sim.send_hpc(Hpc(HPC_POWER_CYCLE, (0, 300)))
        out("  ground: HPC power_cycle(line 0, 300 ms) sent on MAP 63 to the COM UARTs")
        ok &= bool(sim.wait_for(lambda: sim.obc_boots >= 2 and sim.seen("[OBC] time sent"), 20))
        out("  OBC back: pid %d -> %d" % (pid, sim.obc.popen.pid))
        rep = sim.wait_for(lambda: _hptm(sim, NOMINAL, HPC_POWER_CYCLE), 10)
        if rep:
            out(
                "  HPTM from nominal: cpdu 0x%03X, boots %d, HPCs %d, health 0x%02X"
                % (rep.cpdu, rep.boots, rep.hpcs, rep.health)
            )
        ok &= bool(rep)
        sim.stick_req(REDUNDANT)
        out("  fault: redundant controller's CPDU_REQ stuck high")
        ok &= bool(sim.wait_for(lambda: sim.seen("[R] boot 2 (stuck reset)"), 20))
        out("  CPDU lines now 0x%03X (wire: %d latches, %d collisions)" % _wire(sim))
    out("reconfiguration demo %s" % ("ok" if ok else "FAILED"))
    return 0 if ok else 1


def _wire(sim):
    from obsw_sim import reconfig_hal as W

    w = sim.wire()
    return sim.lines(), w[W.LATCHES], w[W.COLLISIONS]


def _hptm(sim, role, code):
    for r in reversed(sim.reports[role]):
        if r.last_hpc == code and r.cpdu & 1:
            return r
    return None
