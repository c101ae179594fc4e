"""Benchmark of autonomous recovery: how long a hung OBC (SIGSTOP of the OBC and every process
it started) takes to serve again, recovered by the simulated reconfiguration module alone
(two MicroPython controllers, the CPDU, the OBC's UART link), against its budget, part by part:

  detection    from the hang to the controller's power-off of the OBC's line: the heartbeat
               deadline the recovery settings give
  power cycle  from power off to power on: the CPDU's off time (off_ms)
  start-up     from power on to the OBC's first word on the UART ("up on line"): 5 s of
               simulated boot plus the process's own start, allowed START_ALLOWANCE (0.5 s)

The goal is the sum of the three budgets. Each part's time comes from the simulation's own
time-stamped log (the fault, the supervisor's power line off and on, the OBC's line); the figures
are the medians over the hangs.

recovery.py [--quick] [--json]
"""

import json
import os
import statistics
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path[:0] = [os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]

from measure import row  # noqa: E402
from obsw_sim.reconfig import ReconfigSim  # noqa: E402

BOOT = 5.0  # s of simulated OBC boot (the OBC process sleeps this long before its first word)
OFF = 0.2  # s the CPDU keeps the OBC's line off in a power cycle (off_ms)
START_ALLOWANCE = 0.5  # s for the OBC process to start, beyond the simulated boot
PARTS = ("detection", "power cycle", "start-up")


def _after(events, t0, text):
    """The time of the first event after ``t0`` whose text holds ``text`` (None if none)."""
    for t, e in events:
        if t >= t0 and text in e:
            return t
    return None


def hang_recoveries(deadline, hangs):
    """Per hang: {"total", "detection", "power cycle", "start-up"} in seconds, from the hang
    to the power-cycled OBC's first word."""
    settings = {"deadline": deadline, "boot_grace": BOOT + 10.0, "off_ms": int(OFF * 1000)}
    settings["max_failures"] = hangs + 1  # power cycles only: no switch-over here
    out = []
    with tempfile.TemporaryDirectory(prefix="obsw-bench-recovery-") as d:
        sim = ReconfigSim(d, recovery=settings, obc_boot_delay=BOOT)
        with sim:
            if not sim.wait_for(lambda: sim.seen("[OBC] context saved"), 60):
                raise RuntimeError("the OBC never came up")
            for i in range(hangs):
                boots = sim.obc_boots
                time.sleep(1.0)
                t = time.monotonic()
                sim.hang_obc()
                ok = sim.wait_for(
                    lambda b=boots: (
                        sim.obc_boots > b
                        and sum(1 for _, e in sim.events if "[OBC] up on line" in e) > b
                    ),
                    deadline + BOOT + 60,
                )
                if not ok:
                    raise RuntimeError("hang %d: the OBC was not recovered" % (i + 1))
                total = time.monotonic() - t
                events = list(sim.events)
                hung = [t for t, e in events if e.startswith("fault: OBC stopped")][-1]
                off = _after(events, hung, "OBC power line off")
                on = _after(events, off, "OBC power line on")
                up = _after(events, on, "[OBC] up on line")
                if None in (off, on, up):
                    raise RuntimeError("hang %d: a part of the recovery is not in the log" % i)
                out.append({"total": total, "detection": off - hung, "power cycle": on - off,
                            "start-up": up - on})  # fmt: skip
    return out


def main(argv):
    quick = "--quick" in argv
    deadline = 2.0 if quick else 5.0
    runs = hang_recoveries(deadline, 1 if quick else 3)
    budget = {"detection": deadline, "power cycle": OFF, "start-up": BOOT + START_ALLOWANCE}
    goal = sum(budget.values())
    median = {k: statistics.median(r[k] for r in runs) for k in ("total",) + PARTS}
    case = "hung OBC to serving again (deadline %.0f s, boot %.0f s)" % (deadline, BOOT)
    rows = [_row(case, "obsw", median["total"]), _row(case, "reference", goal)]
    for part in PARTS:
        what = "%s (budget: %s)" % (part, _BUDGETS[part])
        rows += [_row(what, "obsw", median[part]), _row(what, "reference", budget[part])]
    met = median["total"] <= goal
    note = "recovered in %.2f s against a budget of %.2f s (%s): %s" % (
        median["total"], goal, " + ".join("%s %.2f s" % (p, budget[p]) for p in PARTS),
        "met" if met else "MISSED")  # fmt: skip
    if "--json" in argv:
        print(json.dumps({"bench": "recovery", "rows": rows, "notes": [note]}))
        return 0
    print("%-58s %9s %9s" % ("case", "obsw", "budget"))
    for i in range(0, len(rows), 2):
        print("%-58s %8.2fs %8.2fs" % (rows[i]["case"], rows[i]["value"], rows[i + 1]["value"]))
    print(note)
    return 0


_BUDGETS = {
    "detection": "the heartbeat deadline",
    "power cycle": "the CPDU's off time",
    "start-up": "simulated boot + %.1f s to start" % START_ALLOWANCE,
}


def _row(case, impl, value):
    return row(case, impl, round(value, 3), "s", False)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
