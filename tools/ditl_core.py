#!/usr/bin/env python3
"""A day in the life of the sample spacecraft at the core's level (obsw_sim.ditl: one
process, one injected clock, the 5 MB and 1 MB files across passes): run it, check it, write
its page. The whole chain's day is tools/ditl.py.

python tools/ditl_core.py               24 hours from the orbit's epoch, checked; prints figures
python tools/ditl_core.py --orbits 2    the bounded run (tools/test): two orbits from an hour
                                        before the first pass, smaller files
python tools/ditl_core.py --write       also write docs/ditl-last-run.md and docs/ditl.png

The closing line is 'N passed, N failed' over the checks of the run (exit status 1 if any
failed).
"""

import argparse
import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]

from obsw_host.mission.check import load  # noqa: E402
from obsw_host.ops.passes import from_mission  # noqa: E402
from obsw_sim.ditl import HK, Day  # noqa: E402
from obsw_sim.ditl_checks import checks  # noqa: E402
from obsw_sim.ditl_checks import page as ditl_page  # noqa: E402
from obsw_sim.ditl_checks import utc as _utc  # noqa: E402

MISSION = os.path.join(ROOT, "examples", "sample")


def common(day, f):
    """The figures in the form of obsw_sim.ditl_checks."""
    volume = sum(u[3] for u in f["pass_use"])
    generated = sum(HK[s][1] * f["generated"][s] for s in HK)
    files = {}
    for name, data in (("down", day.down_data), ("up", day.up_data)):
        files[name] = {"size": len(data), "identical": f[name + "_file"], "transactions": None,
                       "progress": [p for _t, p in f[name + "_resumes"]]}  # fmt: skip
    return dict(f, hk_due=sum(f["due"].values()), resends=f["resend_requests"], files=files,
                overflow=f["overflow"] != 0 or volume <= generated,
                store_detail="peak fill %d %%, %d octets of passes against %d generated" % (
                    f["max_store_fill"], volume, generated))  # fmt: skip


def plot(day, f, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t0 = day.start
    fig, ax = plt.subplots(4, 1, figsize=(9, 10))
    ts = [t0 + i * 60.0 for i in range(int((day.end - t0) / 60) + 1)]
    st = day.station
    el = [day.pred.elevation(st, t) for t in ts]
    h = [(t - t0) / 3600 for t in ts]
    ax[0].plot(h, el, lw=0.7)
    ax[0].axhline(st.min_elevation, color="grey", ls="--", lw=0.7)
    for p in day.passes:
        ax[0].axvspan((p.aos - t0) / 3600, (p.los - t0) / 3600, color="tab:green", alpha=0.3)
    for t, _req in day.executed:
        ax[0].axvline((t - t0) / 3600, color="tab:red", lw=0.5)
    ax[0].set_ylim(0, 90)
    ax[0].set_ylabel("elevation (deg)")
    ax[0].set_title("passes over %s (green), planned commands executed (red)" % st.name)
    sh = [(t - t0) / 3600 for t in day.series["t"]]
    ax[1].plot(sh, day.series["fill"])
    ax[1].set_ylabel("store fill (%)")
    ax[1].set_title("the fuller packet store over the day")
    n = range(len(f["pass_use"]))
    ax[2].bar([i - 0.2 for i in n], [u[3] / 1e6 for u in f["pass_use"]], 0.4, label="volume")
    ax[2].bar([i + 0.2 for i in n], [u[2] / 1e6 for u in f["pass_use"]], 0.4, label="sent")
    ax[2].set_xticks(list(n))
    ax[2].set_xticklabels(["pass %d" % (i + 1) for i in n])
    ax[2].set_ylabel("MB")
    ax[2].set_title("link use per pass")
    ax[2].legend()
    ax[3].plot(sh, day.series["generated"], label="generated on board")
    ax[3].plot(sh, day.series["delivered"], label="delivered to the ground")
    ax[3].set_xlabel("hours from %s" % _utc(t0))
    ax[3].set_ylabel("housekeeping reports")
    ax[3].legend()
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def page(day, f, results, seconds, args):
    intro = ("Written by `python tools/ditl_core.py --write` (the rig and its design: "
             "[Operations across passes](passes.md)). %.1f hours of orbit (%.1f orbits) of the "
             "sample spacecraft from %s, computed in %.1f s on one injected clock, loss %g each "
             "way." % (f["hours"], f["orbits"], _utc(day.start), seconds, args.loss))  # fmt: skip
    plan = [(_utc(s.time), _utc(te), "`%s`" % s.request)
            for s, (te, _req) in zip(sorted(day.plan, key=lambda s: s.time),
                                     sorted(day.executed))]  # fmt: skip
    return ditl_page(intro, "the day: passes, store fill, link use, data generated and delivered",
                     results, day.passes, f["pass_use"], "sent (octets)", plan,
                     "executed (onboard)")  # fmt: skip


def main(argv=None):
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawTextHelpFormatter
    )
    ap.add_argument("--orbits", type=float, help="a bounded run of this many orbits")
    ap.add_argument("--hours", type=float, default=24.0, help="the full run's length")
    ap.add_argument("--loss", type=float, default=1e-3, help="share of packets lost each way")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--write", action="store_true", help="write docs/ditl-last-run.md, ditl.png")
    args = ap.parse_args(argv)
    m = load(MISSION)
    pred = from_mission(m.config.doc)
    t0 = pred.tle.epoch.timestamp()
    if args.orbits:
        first = pred.passes(t0, t0 + 86400, pred.stations[:1])[0]
        start = first.aos - 3600.0
        seconds = args.orbits * 86400.0 / pred.tle.mean_motion
        day = Day(pred, start, seconds, down_file=2_000_000, up_file=500_000, loss=args.loss,
                  seed=args.seed)  # fmt: skip
    else:
        day = Day(pred, t0, args.hours * 3600, loss=args.loss, seed=args.seed)
    began = time.monotonic()
    f = day.run()
    took = time.monotonic() - began
    results = checks(common(day, f), full=not args.orbits)
    for name, ok, detail in results:
        print("%s %s: %s" % ("ok  " if ok else "FAIL", name, detail))
    print("%.1f h of orbit in %.1f s" % (f["hours"], took))
    if args.write:
        plot(day, f, os.path.join(ROOT, "docs", "ditl.png"))
        with open(os.path.join(ROOT, "docs", "ditl-last-run.md"), "w") as out:
            out.write(page(day, f, results, took, args))
        print("wrote docs/ditl-last-run.md and docs/ditl.png")
    bad = sum(1 for r in results if not r[1])
    print("%d passed, %d failed" % (len(results) - bad, bad))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
