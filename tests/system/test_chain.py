"""The twelve-step chain end to end (``obsw_sim.chain``), then its faults: each OBC process
killed in turn, bus A cut, UART A cut, the whole OBC killed and power-cycled by the
reconfiguration module on an essential TC, the whole OBC hung and power-cycled by the module
alone. It runs for the sample (in three processes) and for aurora (its own processes, its
plug-in component among them; other APIDs, SCID, VCs, node ids, CPDU names and the OBC on
another CPDU line). Every wait has a deadline; the figures are printed, nothing asserts on
time."""

import os
import signal
import time

import pytest
from obsw.reconfig.essential import HPC_POWER_CYCLE, Hpc
from obsw.spacecan.master import MASTER
from obsw_sim.chain import Chain
from obsw_sim.reconfig import micropython_binary

pytestmark = pytest.mark.skipif(
    micropython_binary() is None or not hasattr(os, "openpty"),
    reason="needs the MicroPython unix port and pseudo-terminals",
)

WAIT = 60.0
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
MISSIONS = {  # name -> (mission folder, processes: None for the mission's own)
    "sample": (os.path.join(ROOT, "examples", "sample"), Chain.SAMPLE_PROCESSES),
    "aurora": (os.path.join(ROOT, "examples", "aurora"), None),
}


def wait_for(predicate, timeout=WAIT, step=0.05):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        v = predicate()
        if v:
            return v
        time.sleep(step)
    return predicate()


class Ledger:
    """Every TC sent through the chain: none that was accepted may stay without completion."""

    def __init__(self, chain):
        self.chain = chain
        self.sent = []

    def ping(self, timeout=3.0):
        try:
            tx = self.chain.ground.ping(timeout=timeout)
        except Exception as e:  # a timeout: the transaction is inside the exception
            tx = getattr(e, "transaction", None)
        if tx is not None:
            self.sent.append(tx)
        return tx is not None and tx.ok

    def ping_until_ok(self, timeout=WAIT):
        """Ping until one completes (the ground repeats a TC that was never accepted)."""
        end = time.monotonic() + timeout
        tries = 0
        while time.monotonic() < end:
            tries += 1
            if self.ping():
                return tries
        log = "\n".join("%6.2f %s" % e for e in self.chain.sim.events[-40:])
        raise AssertionError("no ping completed within %ss\n%s" % (timeout, log))

    def lost(self):
        self.chain.ground.poll(0.5)  # late reports still on their way
        return [
            tx.verification()
            for tx in self.sent
            if "acceptance success" in tx.verification()
            and "completion success" not in tx.verification()
        ]


def restored_context(chain):
    """(boots, saves, sequence counts kept) of the context the OBC in service read back
    through the module at its last start (its log line)."""
    import re

    mark = "module link: context restored: "
    lines = [text for _, text in chain.sim.events if mark in text]
    assert lines, "no context restored through the module"
    text = lines[-1]
    boots = int(re.search(r"boots=(\d+)", text).group(1))
    saves = int(re.search(r"saves=(\d+)", text).group(1))
    return boots, saves, re.search(r"seq=(\{[^}]*\})", text).group(1) != "{}"


def in_stride(chain):
    """The OBC in its stride: since its last start a context save that carries its TM counts
    reached the module (its heartbeats flow on the same UARTs), and no TC frame is
    outstanding."""
    texts = [text for _, text in chain.sim.log_lines()]
    starts = [i for i, t in enumerate(texts) if "module link: context restored" in t
              or "module link: no context kept" in t]  # fmt: skip
    kept = starts and any(
        "module link: context kept by" in t and "TM counts" in t for t in texts[starts[-1] :]
    )
    return bool(kept) and chain.station.ground.fop.outstanding == 0


def master_proxy(chain):
    from obsw.il.node import Node
    from obsw_host.il.transport import SocketTransport

    node = Node("chain-test")
    transport = SocketTransport(node, chain.config.il_directory, listen=False)
    return node.proxy(MASTER, timeout=5.0, retries=2), transport


@pytest.mark.parametrize("mission", sorted(MISSIONS))
def test_twelve_steps_and_faults(mission, tmp_path, capsys):
    figures = []
    t_start = time.monotonic()
    folder, processes = MISSIONS[mission]
    with Chain(str(tmp_path), mission=folder, processes=processes) as chain:
        obc_bit = chain.obc_bit  # the line powering the OBC stays on
        led = Ledger(chain)
        figures.append(("chain up (first ping through frames)", chain.wait_up(WAIT)))

        # the twelve steps: procedure -> CPDU lines -> housekeeping, all through TM frames
        t = time.monotonic()
        tx, end = chain.switch(0x005, timeout=20.0)
        assert tx.ok, tx.verification()
        assert end == "obcp.finished"
        assert wait_for(lambda: chain.lines() == 0x005 | obc_bit)
        figures.append(("CPDU switch: TC[18,3] to obcp.finished", time.monotonic() - t))
        hk = wait_for(lambda: chain.cpdu_housekeeping()["state_bits"] == 5 | obc_bit)
        assert hk
        assert chain.sim.seen("[N] function 1 {1: %d} -> True" % (5 | obc_bit))

        # each OBC process killed in turn: restarted, and the chain serves again
        for name in chain.config.processes:
            # the platform names a process up at its first heartbeat, which may follow the
            # first ping under load
            pid = wait_for(lambda n=name: chain.pid_of(n))
            assert pid is not None, name
            t = time.monotonic()
            os.kill(pid, signal.SIGKILL)
            assert wait_for(lambda n=name, p=pid: chain.pid_of(n) not in (None, p)), name
            tries = led.ping_until_ok()
            figures.append(("%s killed: back in service (%d pings)" % (name, tries),
                            time.monotonic() - t))  # fmt: skip
        tx, end = chain.switch(0x003, name="after_restarts", timeout=20.0)
        assert (tx.ok, end) == (True, "obcp.finished")
        assert wait_for(lambda: chain.lines() == 0x003 | obc_bit)

        # bus A cut: the SpaceCAN traffic moves to bus B
        master, transport = master_proxy(chain)
        try:
            chain.sim.hub.kill(0)
            t = time.monotonic()
            tx, end = chain.switch(0x007, name="bus_b", timeout=20.0)
            assert (tx.ok, end) == (True, "obcp.finished")
            assert wait_for(lambda: chain.lines() == 0x007 | obc_bit)
            figures.append(("bus A cut: switch completed on bus B", time.monotonic() - t))
            assert master.active_bus == 1
        finally:
            chain.sim.hub.revive(0)
            transport.close()

        # UART A cut: link B carries on
        chain.links[0].enabled = False
        t = time.monotonic()
        tries = led.ping_until_ok()
        tx, end = chain.switch(0x00F, name="uart_b", timeout=20.0)
        assert (tx.ok, end) == (True, "obcp.finished")
        figures.append(("UART A cut: ping and switch over UART B (%d pings)" % tries,
                        time.monotonic() - t))  # fmt: skip
        chain.links[0].enabled = True

        assert led.lost() == []  # no TC that was accepted went without its completion

        # the OBC killed: only an essential TC to the reconfiguration module brings it back
        chain.platform.update(max_failures=2, window=120.0)  # for the OBC's next boot
        boots = chain.sim.obc_boots
        chain.sim.kill_obc()
        assert not led.ping(timeout=1.0)
        t = time.monotonic()
        chain.sim.send_hpc(Hpc(HPC_POWER_CYCLE, (chain.obc_line, 200)))
        assert chain.sim.wait_for(lambda: chain.sim.obc_boots == boots + 1, WAIT)
        tries = led.ping_until_ok()
        figures.append(("OBC killed: power-cycled by an essential TC, serving again (%d pings)"
                        % tries, time.monotonic() - t))  # fmt: skip
        # its context came back through the module's UART link and safeguard memory
        boots, saves, counts = restored_context(chain)
        assert boots >= 1 and saves >= 1 and counts, (boots, saves)
        tx, end = chain.switch(0x005, name="after_power_cycle", timeout=20.0)
        assert (tx.ok, end) == (True, "obcp.finished")
        assert wait_for(lambda: chain.lines() == 0x005 | obc_bit)

        # a process failing again and again: the platform manager asks the reconfiguration
        # module, through the CPDU node, to power-cycle the whole OBC
        boots = chain.sim.obc_boots
        t = time.monotonic()
        for _ in range(2):
            pid = chain.pid_of("core")
            os.kill(pid, signal.SIGKILL)
            assert wait_for(lambda p=pid: chain.pid_of("core") not in (None, p))
        assert chain.sim.wait_for(lambda: chain.sim.obc_boots == boots + 1, WAIT)
        assert chain.sim.seen("asking %s to power-cycle the OBC" % chain.power_cycler)
        tries = led.ping_until_ok()
        figures.append(("2 failures: platform manager had the OBC power-cycled (%d pings)"
                        % tries, time.monotonic() - t))  # fmt: skip

        # the whole OBC hung (every process stopped): the reconfiguration module misses its
        # SpaceCAN heartbeat and power-cycles it by itself, without any ground TC
        led.ping_until_ok()
        assert wait_for(lambda: in_stride(chain))
        boots = chain.sim.obc_boots
        t = time.monotonic()
        chain.sim.hang_obc()
        assert chain.sim.wait_for(
            lambda: chain.sim.seen("recovery: power_cycle line %d" % chain.obc_line), WAIT
        )
        assert chain.sim.wait_for(lambda: chain.sim.obc_boots == boots + 1, WAIT)
        try:
            tries = led.ping_until_ok()
        except AssertionError:
            fop = chain.station.ground.fop
            raise AssertionError("FOP-1 state %r, vs %r" % (fop.state, fop.vs)) from None
        figures.append(("OBC hung: power-cycled by the module alone, serving again (%d pings)"
                        % tries, time.monotonic() - t))  # fmt: skip
        tx, end = chain.switch(0x003, name="after_hang", timeout=20.0)
        assert (tx.ok, end) == (True, "obcp.finished")
    with capsys.disabled():
        took = time.monotonic() - t_start
        print("\n  %s: 12-step chain and faults, %.1f s in all:" % (mission, took))
        for what, seconds in figures:
            print("    %-70s %6.2f s" % (what, seconds))


def test_switch_over_to_the_redundant_obc(tmp_path, capsys):
    """The OBC is killed and the reconfiguration module power-cycles it by itself; it comes
    back with its context; then it hangs: with one recovery already in the window the module
    switches to the redundant OBC (a second `obsw obc serve` of the mission, its own state
    folder, another CPDU line), which carries on the context, answers the ground through the
    same UARTs and runs procedures; no TC that was accepted is left without its completion."""
    figures = []
    recovery = {"deadline": 4.0, "max_failures": 1, "window": 300.0}
    with Chain(str(tmp_path), recovery=recovery) as chain:
        led = Ledger(chain)
        figures.append(("chain up (first ping through frames)", chain.wait_up(WAIT)))
        nominal = chain.obc_line
        faults = (("killed", chain.sim.kill_obc, "power_cycle"),
                  ("hung", chain.sim.hang_obc, "switch_over"))  # fmt: skip
        for fault, inject, decision in faults:  # no ground TC: the module acts by itself
            led.ping_until_ok()
            assert wait_for(lambda: in_stride(chain))
            boots = chain.sim.obc_boots
            t = time.monotonic()
            inject()
            seen = "recovery: %s line %d" % (decision, nominal)
            assert chain.sim.wait_for(lambda s=seen: chain.sim.seen(s), WAIT), "%s\n%s" % (
                seen,
                "\n".join("%6.2f %s" % e for e in chain.sim.log_lines()[-60:]),
            )
            assert chain.sim.wait_for(lambda b=boots: chain.sim.obc_boots == b + 1, WAIT)
            tries = led.ping_until_ok()
            figures.append(("OBC %s: %s, serving again (%d pings)" % (fault, decision, tries),
                            time.monotonic() - t))  # fmt: skip
            assert restored_context(chain)[2], "the TM counts did not come back"
        assert chain.active_line == chain.REDUNDANT_LINE
        # the redundant OBC carries on the nominal's context: its boots, its TM counts
        boots, saves, counts = restored_context(chain)
        assert boots >= 2 and saves >= 1 and counts, (boots, saves)
        assert chain.sim.lines() >> nominal & 1 == 0  # the nominal OBC stays off
        assert chain.sim.seen("supervisor: redundant OBC power line on")
        assert os.listdir(chain.state + "-redundant")  # its own state folder
        t = time.monotonic()
        tx, end = chain.switch(0x006, name="on_the_redundant", timeout=20.0)
        assert (tx.ok, end) == (True, "obcp.finished")
        assert wait_for(lambda: chain.lines() == 0x006 | chain.obc_bit)
        figures.append(("redundant OBC: CPDU switch by procedure", time.monotonic() - t))
        assert led.lost() == []
    with capsys.disabled():
        print("\n  switch-over to the redundant OBC:")
        for what, seconds in figures:
            print("    %-70s %6.2f s" % (what, seconds))
