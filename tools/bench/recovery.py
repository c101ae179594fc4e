"""Benchmark of autonomous recovery: how long a hung OBC (SIGSTOP of the OBC and every process
it started) takes to serve again, recovered by the simulated reconfiguration module alone
(two MicroPython controllers, the CPDU, the OBC's UART link), next to the goal: the configured
deadline plus 5 s of simulated boot.

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

from obsw_sim.reconfig import ReconfigSim  # noqa: E402

BOOT = 5.0  # s of simulated OBC boot (the OBC process sleeps this long before its first word)


def hang_recoveries(deadline, hangs):
    """Seconds from each hang to the first heartbeat of the power-cycled OBC."""
    settings = {"deadline": deadline, "boot_grace": BOOT + 10.0, "off_ms": 200}
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
                out.append(time.monotonic() - t)
    return out


def main(argv):
    quick = "--quick" in argv
    deadline = 2.0 if quick else 5.0
    times = hang_recoveries(deadline, 1 if quick else 3)
    ours = statistics.median(times)
    goal = deadline + BOOT
    case = "hung OBC to serving again (deadline %.0f s, boot %.0f s)" % (deadline, BOOT)
    if "--json" in argv:
        rows = [
            {"case": case, "impl": "obsw", "value": ours, "unit": "s", "higher_is_better": False},
            {
                "case": case,
                "impl": "reference",
                "value": goal,
                "unit": "s",
                "higher_is_better": False,
            },
        ]
        print(json.dumps({"bench": "recovery", "rows": rows}))
        return 0
    print("%-58s %9s %9s %7s" % ("case", "obsw", "goal", "ratio"))
    print("%-58s %8.2fs %8.2fs %7.2f" % (case, ours, goal, ours / goal))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
