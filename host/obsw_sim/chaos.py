"""The chaos campaign: the whole chain (``obsw_sim.chain``: ground, TC/TM frames on two
UARTs, the OBC's processes under its platform manager, SpaceCAN, both reconfiguration
controllers as MicroPython processes, the UART link to the module, CFDP, OBCPs) run for a given
time while random faults are injected, and what was lost counted.

Faults, one at a time, drawn from ``--seed``: a kill or a hang (SIGSTOP) of each OBC process, of
the whole OBC and of one reconfiguration controller; a cut of CAN bus A or B; a cut of UART A
or B; a spell of TC frame loss and duplication on the UARTs; a power cut of the OBC while a
CFDP file is on its way. Between faults the ground sends pings, switches CPDU lines by PLUTO
procedure and puts files by CFDP (class 2), and the OBC sends periodic housekeeping.

It checks, and prints:
- every TC the OBC accepted completed or was reported failed, except those in flight when the
  OBC (or its PUS process) was killed or cut from power: those are declared, with their fault;
- the periodic housekeeping contiguous (no report missing) except for gaps while a fault was
  on: declared gaps;
- every CFDP transfer delivered byte-identical, or reported failed by the sender;
- the recovery time of each fault kind (injection to the first completed ping; p50, p99, n),
  next to the goals (a killed unit: 2 s; a hung OBC: the module's deadline + 5 s of boot);
- memory flat: the spacecraft's RSS (both controllers; the OBC and every process it started)
  at the end within a quarter of the start's; the ground's (it keeps every record) is shown.
Exit status 0 only when nothing undeclared was lost, every fault was recovered from and the
spacecraft's memory stayed flat.
"""

import argparse
import json
import os
import random
import signal
import subprocess
import sys
import tempfile
import time

from obsw_sim.chain import Chain
from obsw_sim.reconfig import descendants

KILL_GOAL = 2.0  # s: a killed unit serves again (issue's goal)
BOOT = 5.0  # s of boot the goal for a hung OBC allows on top of the module's deadline
RECOVERY = {"deadline": 4.0, "boot_grace": 20.0, "off_ms": 300, "max_failures": 1000}
MEMORY_GROWTH = 1.25  # the spacecraft's RSS at the end may exceed the start's by a quarter
MEMORY_SLACK_KB = 1024  # and a megabyte (a unit restarting at the very end)
WAIT = 60.0  # s any fault may take to be recovered from before it counts as not recovered
PING_WAIT = 0.5  # s a recovery ping waits for its completion
HK_SID = 1  # the sample's periodic housekeeping: every 10 cycles of 0.1 s
HK_PERIOD = 1.0
HK_MISSING = 2.5  # a silence this many periods long means reports are missing
FAULTS = (
    "process_kill",
    "process_hang",
    "obc_kill",
    "obc_hang",
    "controller_kill",
    "can_cut",
    "uart_cut",
    "frame_loss",
    "power_cut_during_cfdp",
)


def percentile(values, q):
    if not values:
        return None
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))]


def rss_kb(pid):
    try:
        with open("/proc/%d/status" % pid) as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return None


class Campaign:
    """One campaign on the chain in ``work`` (see the module text)."""

    def __init__(self, work, seed=1, out=print):
        self.work = work
        self.rng = random.Random(seed)
        self.out = out
        self.chain = Chain(work, recovery=RECOVERY)
        self.sent = []  # (tx, sent at)
        self.faults = []  # {"kind", "at", "until", "recovered", "took", "kills"}
        self.transfers = []  # {"name", "ok", "reported"}
        self.hk_counts = []  # (arrival time, sequence count) of each periodic TM[3,25]
        self._seen = 0
        self.ground_root = os.path.join(work, "ground-files")
        os.makedirs(self.ground_root)

    # -------------------------------------------------------------------------- traffic

    def ping(self, timeout=2.0):
        g = self.chain.ground
        try:
            tx = g.ping(timeout=timeout)
        except Exception as e:  # a timeout: its transaction rides on the exception
            tx = getattr(e, "transaction", None)
        if tx is not None:
            self.sent.append((tx, time.monotonic()))
        self._collect()
        return tx is not None and tx.ok

    def _collect(self):
        g = self.chain.ground
        for tm, _ in g.received[self._seen :]:
            if (tm.service, tm.subtype) == (3, 25):
                self.hk_counts.append((time.monotonic(), tm.seq_count))
        self._seen = len(g.received)

    def serving(self, timeout=WAIT):
        """Ping until one completes; the seconds it took, or None. Each ping waits
        ``PING_WAIT`` for its completion: a ping lost to the fault costs no more than that
        (the resolution of the recovery times)."""
        t0 = time.monotonic()
        while time.monotonic() - t0 < timeout:
            if self.ping(PING_WAIT):
                return time.monotonic() - t0
        return None

    def cfdp_put(self, size=20000, kill_obc_after=None):
        """A class 2 put of a new file to the OBC; True when it arrived byte-identical, False
        when the sender reported it failed; None when neither (lost)."""
        c = self.chain
        name = "chaos-%d.bin" % len(self.transfers)
        data = bytes(self.rng.getrandbits(8) for _ in range(size))
        with open(os.path.join(self.ground_root, name), "wb") as f:
            f.write(data)
        env = dict(os.environ, OBSW_MISSION=c.mission_dir)
        cmd = [sys.executable, "-m", "obsw_host.cli", "cfdp", "put", name]
        cmd += ["--root", self.ground_root, "--port", str(c.cfdp_ground_port)]
        cmd += ["--peer", "%d=127.0.0.1:%d" % (c.ids.cfdp_entities[0], c.cfdp_port)]
        cmd += ["--class", "2", "--timeout", "40"]
        put = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
        if kill_obc_after is not None:
            time.sleep(kill_obc_after)
            c.sim.kill_obc()
        out = put.communicate(timeout=120)[0].decode(errors="replace")
        arrived = None
        for state in (c.state, c.state + "-redundant"):
            path = os.path.join(state, "files", name)
            if os.path.exists(path):
                with open(path, "rb") as f:
                    arrived = f.read()
        ok = put.returncode == 0 and arrived == data
        reported = put.returncode != 0  # the sender said it failed
        self.transfers.append({"name": name, "ok": ok, "reported": reported, "said": out[-200:]})
        return ok

    # -------------------------------------------------------------------------- faults

    def inject(self, kind):
        c = self.chain
        at = time.monotonic()
        fault = {"kind": kind, "at": at, "until": None, "took": None, "kills": False}
        self.faults.append(fault)
        self.out("  %7.1f s  %s" % (at - self.t0, kind))
        if kind in ("process_kill", "process_hang"):
            name = self.rng.choice(sorted(c.config.processes))
            pid = c.pid_of(name)
            fault["process"] = name
            fault["kills"] = name == "core"  # the PUS process: TCs in it are gone
            try:
                os.kill(pid, signal.SIGKILL if kind == "process_kill" else signal.SIGSTOP)
            except (TypeError, ProcessLookupError):
                fault["gone"] = True  # already restarting (or never up): nothing to do
        elif kind == "obc_kill":
            fault["kills"] = True
            c.sim.kill_obc()
        elif kind == "obc_hang":
            fault["kills"] = True
            c.sim.hang_obc()
        elif kind == "controller_kill":
            role = self.rng.choice((0, 1))
            fault["controller"] = role
            ctrl = c.sim.ctrl[role]
            if ctrl is not None:
                ctrl.kill()  # the module's supervisor resets it
        elif kind == "can_cut":
            bus = self.rng.choice((0, 1))
            c.sim.hub.kill(bus)
            name = "chaos%d" % len(self.faults)  # its own: an earlier one may still be loaded
            try:
                tx, end = c.switch(self.rng.choice((0x005, 0x003)), name=name, timeout=20.0)
                fault["switched"] = bool(tx.ok and end == "obcp.finished")
            except Exception as e:  # a timeout: the procedure did not complete
                fault["switched"] = False
                fault["error"] = str(e)
            finally:
                c.sim.hub.revive(bus)
            try:
                c.obcp.stop_and_unload(name, timeout=5.0)
            except Exception:
                pass  # best effort: the OBC may be restarting
        elif kind == "uart_cut":
            link = self.rng.choice(c.links)
            link.enabled = False
            try:
                fault["took"] = self.serving()
            finally:
                link.enabled = True
        elif kind == "frame_loss":
            self._lossy(seconds=8.0, loss=0.1, dup=0.05)
        elif kind == "power_cut_during_cfdp":
            fault["kills"] = True
            self.cfdp_put(size=200000, kill_obc_after=self.rng.uniform(0.2, 1.0))
        if fault["took"] is None:
            fault["took"] = self.serving()
        fault["until"] = time.monotonic()
        fault["recovered"] = fault["took"] is not None and fault.get("switched", True)
        if not fault["recovered"]:
            fault["state"] = self.diagnosis()
            self.out("           not recovered: %s" % fault["state"])
        return fault

    def diagnosis(self):
        """What a fault not recovered from left: the ground station's FOP-1, its thread, the
        simulation's last lines."""
        c = self.chain
        fop = c.station.ground.fop
        events = c.sim.log_lines()
        return {
            "fop_state": fop.state,
            "fop_vs": fop.vs,
            "station_alive": c.station_alive,
            "last": [text for _, text in events[-6:]],
            "loop_errors": sorted({t for _, t in events if "loop error" in t})[:4],
        }

    def _lossy(self, seconds, loss, dup):
        """TC frames lost and duplicated on the way to the OBC for ``seconds``."""
        links = self.chain.links
        writes = [link.write for link in links]
        rng = self.rng

        def lossy(write):
            def w(data):
                if rng.random() < loss:
                    return
                write(data)
                if rng.random() < dup:
                    write(data)

            return w

        for link, write in zip(links, writes):
            link.write = lossy(write)
        try:
            end = time.monotonic() + seconds
            while time.monotonic() < end:
                self.ping()
        finally:
            for link in links:
                del link.write  # the class's own again

    # -------------------------------------------------------------------------- the run

    def memory(self):
        """RSS in kB of the spacecraft's processes (both controllers; the OBC and every
        process it started) and of this process, the ground, which keeps every record of
        the run (each TC, housekeeping report and fault) for the verdict."""
        sim = self.chain.sim
        ctrl = [p.popen.pid for p in sim.ctrl if p is not None]
        obc = [sim.obc.popen.pid] + descendants(sim.obc.popen.pid) if sim.obc else []
        kb = lambda pids: sum(rss_kb(p) or 0 for p in pids)  # noqa: E731
        return {"controllers": kb(ctrl), "OBC": kb(obc), "ground": kb([os.getpid()])}

    def run(self, minutes, gap=(2.0, 6.0)):
        c = self.chain
        c.start()
        self.t0 = time.monotonic()
        c.ground.keep_unsolicited = 10**7
        try:
            c.wait_up(WAIT)
            c.ground.enable_hk([HK_SID])
            self.serving()
            rss0 = self.memory()
            end = self.t0 + 60.0 * minutes
            n = 0
            while time.monotonic() < end:
                quiet = time.monotonic() + self.rng.uniform(*gap)
                while time.monotonic() < quiet:
                    self.ping()
                    time.sleep(0.1)
                if n % 4 == 3:
                    self.cfdp_put()
                kinds = FAULTS
                self.inject(kinds[n % len(kinds)] if n < len(kinds) else self.rng.choice(kinds))
                n += 1
            self.serving()
            time.sleep(2.0)  # the last reports on their way
            self._collect()
            rss1 = self.memory()
        finally:
            c.stop()
        return self.report(rss0, rss1)

    # -------------------------------------------------------------------------- the verdict

    def _during_fault(self, t, margin=3.0):
        return next(
            (f for f in self.faults if f["at"] - margin <= t <= (f["until"] or t) + margin), None
        )

    def report(self, rss0, rss1):
        lost, declared = [], []
        for tx, at in self.sent:
            v = tx.verification()
            if "acceptance success" in v and "completion success" not in v:
                if "failure" in " ".join(v):
                    continue  # reported failed
                fault = self._during_fault(at)
                (declared if fault and fault["kills"] else lost).append(
                    "%s at %.1f s" % (tx.tc.seq_count, at - self.t0)
                )
        gaps, declared_gaps = 0, 0
        for (t0, _), (t1, _) in zip(self.hk_counts, self.hk_counts[1:]):
            if t1 - t0 > HK_MISSING * HK_PERIOD:  # reports missing in between
                if self._during_fault(t1, margin=6.0) or self._during_fault(t0, margin=6.0):
                    declared_gaps += 1
                else:
                    gaps += 1
        kinds = {}
        for f in self.faults:
            kinds.setdefault(f["kind"], []).append(f)
        recovery = {}
        for kind, fs in sorted(kinds.items()):
            took = [f["took"] for f in fs if f["took"] is not None]
            recovery[kind] = {
                "n": len(fs),
                "recovered": sum(1 for f in fs if f["recovered"]),
                "p50": percentile(took, 0.5),
                "p99": percentile(took, 0.99),
            }
        transfers = {
            "n": len(self.transfers),
            "delivered": sum(1 for t in self.transfers if t["ok"]),
            "reported_failed": sum(1 for t in self.transfers if not t["ok"] and t["reported"]),
            "lost": [t["name"] for t in self.transfers if not t["ok"] and not t["reported"]],
        }
        result = {
            "minutes": (time.monotonic() - self.t0) / 60.0,
            "tcs": len(self.sent),
            "tcs_lost": lost,
            "tcs_declared": declared,
            "hk_reports": len(self.hk_counts),
            "hk_gaps": gaps,
            "hk_declared_gaps": declared_gaps,
            "transfers": transfers,
            "recovery": recovery,
            "goals": {"process_kill": KILL_GOAL, "obc_hang": RECOVERY["deadline"] + BOOT},
            "rss_kb": {k: [rss0[k], rss1[k]] for k in rss0},
        }
        flat = all(
            rss1[k] <= MEMORY_GROWTH * rss0[k] + MEMORY_SLACK_KB for k in ("controllers", "OBC")
        )
        all_recovered = all(x["recovered"] == x["n"] for x in recovery.values())
        checks = [
            ("no accepted TC lost without a declared cause", not lost),
            ("housekeeping contiguous but for declared gaps", gaps == 0),
            ("every CFDP transfer delivered or reported failed", not transfers["lost"]),
            ("every fault recovered from", all_recovered),
            ("the spacecraft's memory flat (controllers, OBC)", flat),
        ]
        result["checks"] = {name: ok for name, ok in checks}
        return result


def print_result(r, out=print):
    out("chaos campaign: %.1f min, %d TCs, %d housekeeping reports, %d CFDP transfers"
        % (r["minutes"], r["tcs"], r["hk_reports"], r["transfers"]["n"]))  # fmt: skip
    out("  TCs accepted without completion: %d declared (in an OBC killed or cut), %d lost %s"
        % (len(r["tcs_declared"]), len(r["tcs_lost"]), r["tcs_lost"][:5]))  # fmt: skip
    out("  housekeeping: %d gaps while a fault was on (declared), %d other"
        % (r["hk_declared_gaps"], r["hk_gaps"]))  # fmt: skip
    t = r["transfers"]
    out("  CFDP: %d delivered byte-identical, %d reported failed, %d lost"
        % (t["delivered"], t["reported_failed"], len(t["lost"])))  # fmt: skip
    out("  %-24s %4s %9s %8s %8s %8s" % ("fault", "n", "recovered", "p50 s", "p99 s", "goal"))
    for kind, rec in r["recovery"].items():
        goal = r["goals"].get(kind)
        fmt = lambda v: "-" if v is None else "%.2f" % v  # noqa: E731
        out("  %-24s %4d %9d %8s %8s %8s" % (kind, rec["n"], rec["recovered"], fmt(rec["p50"]),
                                            fmt(rec["p99"]), fmt(goal)))  # fmt: skip
    for what, (start, end) in r["rss_kb"].items():
        out("  memory of the %s: %d kB at the start, %d at the end" % (what, start, end))
    passed = sum(1 for ok in r["checks"].values() if ok)
    for name, ok in r["checks"].items():
        out("  %s %s" % ("ok    " if ok else "FAILED", name))
    out("%d passed, %d failed" % (passed, len(r["checks"]) - passed))
    return passed == len(r["checks"])


def markdown(r, seed, minutes):
    """The campaign's page (docs/benchmarks/chaos.md): its figures as the run gave them."""
    t = r["transfers"]
    lines = [
        "# Chaos campaign: the last long run",
        "",
        "Written by `python tools/chaos.py --minutes %g --seed %d --markdown FILE` from the run"
        % (minutes, seed),
        "itself (see [the campaign](chaos.md)); %s UTC, %.1f minutes on this machine."
        % (time.strftime("%Y-%m-%d %H:%M", time.gmtime()), r["minutes"]),
        "",
        "| what | count |",
        "|---|---:|",
        "| TCs sent | %d |" % r["tcs"],
        "| accepted, completion never came, OBC killed or cut meanwhile (declared) | %d |"
        % len(r["tcs_declared"]),
        "| accepted, completion never came, no cause (lost) | %d |" % len(r["tcs_lost"]),
        "| periodic housekeeping reports | %d |" % r["hk_reports"],
        "| housekeeping gaps while a fault was on (declared) | %d |" % r["hk_declared_gaps"],
        "| housekeeping gaps otherwise | %d |" % r["hk_gaps"],
        "| CFDP transfers delivered byte-identical | %d of %d |" % (t["delivered"], t["n"]),
        "| CFDP transfers reported failed by the sender | %d |" % t["reported_failed"],
        "| CFDP transfers lost | %d |" % len(t["lost"]),
    ]
    lines += [
        "| RSS of the %s, start and end (kB) | %d, %d |" % (what, start, end)
        for what, (start, end) in r["rss_kb"].items()
    ]
    lines += [
        "",
        "| fault | n | recovered | p50 (s) | p99 (s) | goal (s) |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for kind, rec in r["recovery"].items():
        cells = [rec["p50"], rec["p99"], r["goals"].get(kind)]
        cells = ["-" if v is None else "%.2f" % v for v in cells]
        row = (kind, rec["n"], rec["recovered"], " | ".join(cells))
        lines.append("| %s | %d | %d | %s |" % row)
    lines += ["", "| check | result |", "|---|---|"]
    lines += ["| %s | %s |" % (k, "ok" if v else "FAILED") for k, v in r["checks"].items()]
    return "\n".join(lines) + "\n"


def main(argv=None):
    p = argparse.ArgumentParser(prog="tools/chaos.py", description=__doc__.splitlines()[0])
    p.add_argument("--minutes", type=float, default=2.0, help="how long to run (default 2)")
    p.add_argument("--seed", type=int, default=1, help="the faults' random seed")
    p.add_argument("--json", help="also write the figures to this file")
    p.add_argument("--markdown", help="also write them as a documentation page to this file")
    args = p.parse_args(argv)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))  # a stopped campaign cleans up
    with tempfile.TemporaryDirectory(prefix="obsw-chaos-") as work:
        r = Campaign(work, args.seed).run(args.minutes)
    ok = print_result(r)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(r, f, indent=1)
    if args.markdown:
        with open(args.markdown, "w") as f:
            f.write(markdown(r, args.seed, args.minutes))
    return 0 if ok else 1
