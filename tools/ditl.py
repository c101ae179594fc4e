#!/usr/bin/env python3
"""A day in the life of the whole chain (obsw_sim.ditl_chain) under time acceleration.

python tools/ditl.py                    24 hours at 52 times (28 minutes here), checked
python tools/ditl.py --orbits 2         a bounded run: two orbits at 48 times (4 minutes)
python tools/ditl.py --write            also write docs/ditl-last-run.md and docs/ditl.png

It starts itself again under libfaketime (obsw_sim.faketime: every process of the chain on one
clock, SPEED times faster), the clock set so that the day begins ``--before`` seconds before
the first pass over the mission's first station after now. The downlink runs at ``--downlink``
bit/s (default: the station's), the file up's data at ``--up-rate`` octets/s. The closing
line is 'N passed, N failed' over the checks of the run (exit status 1 if any failed).
"""

import argparse
import os
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]

from obsw_host.mission.check import load  # noqa: E402
from obsw_host.ops.passes import from_mission  # noqa: E402
from obsw_sim import faketime  # noqa: E402
from obsw_sim.ditl_checks import checks  # noqa: E402
from obsw_sim.ditl_checks import page as ditl_page  # noqa: E402
from obsw_sim.ditl_checks import utc as _utc  # noqa: E402

MISSION = os.path.join(ROOT, "examples", "sample")


def common(day, f):
    """The figures in the form of obsw_sim.ditl_checks."""
    files = {}
    for name in ("down", "up"):
        same, count, prog = f["files"][name]
        files[name] = {"size": f[name + "_size"], "identical": same, "transactions": count,
                       "progress": prog}  # fmt: skip
    return dict(f, passes=f["contacts"], files=files,
                overflow=f["max_backlog"] >= f["store_size"],
                store_detail="largest backlog %d octets of %d" % (
                    f["max_backlog"], f["store_size"]))  # fmt: skip


def plot(day, f, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t0 = day.start
    fig, ax = plt.subplots(5, 1, figsize=(9, 12))
    ts = [t0 + i * 60.0 for i in range(int(day.seconds / 60) + 1)]
    st = day.station
    el = [day.pred.elevation(st, t) for t in ts]
    h = lambda t: (t - t0) / 3600  # noqa: E731
    ax[0].plot([h(t) for t in ts], el, lw=0.7)
    ax[0].axhline(st.min_elevation, color="grey", ls="--", lw=0.7)
    for p in day.passes:
        ax[0].axvspan(h(p.aos), h(p.los), color="tab:green", alpha=0.3)
    ax[0].set_ylim(0, 90)
    ax[0].set_ylabel("elevation (deg)")
    ax[0].set_title("passes over %s (green)" % st.name)
    from obsw_host.pus.tai import TAI_MINUS_UNIX

    backlog = sorted(day.backlog)  # by the reports' time tags: the dumps bring them late
    ax[1].plot([h(t - TAI_MINUS_UNIX) for t, _ in backlog], [v / 1e3 for _, v in backlog])
    ax[1].set_ylabel("kB")
    ax[1].set_title("the stores' backlog on board (Passes.backlog), store size %d kB" % (
        f["store_size"] / 1e3))  # fmt: skip
    n = range(len(f["pass_use"]))
    ax[2].bar(list(n), [u[2] for u in f["pass_use"]], 0.6)
    ax[2].set_xticks(list(n))
    ax[2].set_xticklabels(["pass %d" % (i + 1) for i in n])
    ax[2].set_ylabel("packets down")
    ax[2].set_title("link use per pass")
    ax[3].plot([h(t) for t in day.series["t"]], day.series["generated"],
               label="generated on board")  # fmt: skip
    ax[3].plot([h(t) for t in day.series["t"]], day.series["delivered"],
               label="delivered to the ground")  # fmt: skip
    ax[3].set_ylabel("reports")
    ax[3].set_title("high-priority housekeeping (one report every %g s on board)" % day.hk_period)
    ax[3].legend()
    planned = [(s.time, i) for i, s in enumerate(day.plan) if s.time < day.end]
    ax[4].scatter([h(t) for t, _ in planned], [0] * len(planned), marker="|", s=200,
                  label="planned")  # fmt: skip
    ex = [(day.started.get(i, day.executed[i]) - TAI_MINUS_UNIX) for _, i in planned
          if i in day.executed]  # fmt: skip
    ax[4].scatter([h(t) for t in ex], [1] * len(ex), marker="|", s=200, label="executed")
    ax[4].set_yticks([0, 1])
    ax[4].set_yticklabels(["planned", "executed"])
    ax[4].set_xlabel("hours from %s" % _utc(t0))
    ax[4].set_title("commands planned and executed (onboard time)")
    for a in ax:
        a.set_xlim(0, day.seconds / 3600)
    ax[2].set_xlim(-0.5, max(len(f["pass_use"]), 1) - 0.5)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def page(day, f, results, took, speed):
    from obsw_host.pus.tai import TAI_MINUS_UNIX

    plan = []
    for i, s in enumerate(day.plan):
        te = day.started.get(i, day.executed.get(i)) if i in day.executed else None
        plan.append((_utc(s.time), _utc(te - TAI_MINUS_UNIX) if te else "not seen",
                     "`%s`" % s.request))  # fmt: skip
    files = ["| file | octets | identical | transactions | at each AOS (octets) |",
             "|---|---|---|---|---|"]  # fmt: skip
    for name in ("down", "up"):
        same, count, prog = f["files"][name]
        files.append("| %s | %d | %s | %d | %s |" % (name, f[name + "_size"], same, count,
                                                     ", ".join(str(p) for p in prog)))  # fmt: skip
    for t, kind, info in day.cfdp_log:
        if kind in ("finished", "fault", "abandoned"):
            files.append("")
            octets = info.get("size", info.get("progress"))
            files.append("- %s: %s, condition %s, %s octets" % (
                _utc(t), kind, info.get("condition"), octets))  # fmt: skip
    files = ["The receiver's octets at each AOS: for the file down the ground's (the start of "
             "its first gap), for the file up what the ground had sent (the receiver is on "
             "board).", "", *files]  # fmt: skip
    intro = (
        "Written by `python tools/ditl.py --write` (the rig and its design: "
        "[Operations across passes](passes.md)). %.1f hours of orbit (%.1f orbits) of the "
        "sample spacecraft from %s, the whole chain (the OBC's processes, both reconfiguration "
        "controllers, frames on the UARTs, the station, the ground) under libfaketime at %g "
        "times: %.0f s here; the downlink at %d bit/s, files through the frames. Power "
        "cycles of the OBC by its module: %d; processes restarted by its platform manager: "
        "%d; controllers reset: %d."
        % (
            f["hours"],
            f["orbits"],
            _utc(day.start),
            speed,
            took,
            day.downlink_bps,
            max(0, (f["obc_boots"] or 1) - 1),
            f["process_restarts"],
            f["controller_resets"],
        )
    )
    return ditl_page(intro, "the day: passes, store backlog, link use, data delivered, commands",
                     results, day.passes, f["pass_use"], "packets down", plan,
                     "started (onboard, UTC)", files)  # fmt: skip


def main(argv=None):
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawTextHelpFormatter
    )
    ap.add_argument("--orbits", type=float, help="a bounded run of this many orbits")
    ap.add_argument("--hours", type=float, default=24.0, help="the full run's length")
    ap.add_argument("--speed", type=float, help="times faster (default 52, bounded run 48)")
    ap.add_argument("--downlink", type=float, help="downlink bit/s (the station's)")
    ap.add_argument("--before", type=float, default=1800.0,
                    help="seconds of orbit before the first pass (default 1800)")  # fmt: skip
    ap.add_argument("--down", type=int, help="octets of the file down (5 MB; bounded 2.4 MB)")
    ap.add_argument("--up", type=int, help="octets of the file up (1 MB; bounded 600 kB)")
    ap.add_argument(
        "--up-rate",
        type=float,
        default=900.0,
        help="octets/s of the file up's data (900: 7.2 of the 9.6 kbit/s uplink)",
    )
    ap.add_argument("--write", action="store_true", help="write docs/ditl-last-run.md, ditl.png")
    ap.add_argument("--work", help="folder for the chain's files (default: a temporary one)")
    args = ap.parse_args(argv)
    m = load(MISSION)
    pred = from_mission(m.config.doc)
    speed = args.speed or (48.0 if args.orbits else 52.0)
    if faketime.active() is None:  # start again, the whole process tree on the fast clock
        now = time.time()
        passes = pred.passes(now, now + 2 * 86400, pred.stations[:1])
        first = passes[0]
        if args.orbits:  # a bounded run begins before a pass that another follows within it
            orbit_s = 86400.0 / pred.tle.mean_motion
            span = args.orbits * orbit_s - args.before
            first = next((a for a, b in zip(passes, passes[1:]) if b.los - a.aos < span),
                         first)  # fmt: skip
        offset = first.aos - args.before - now
        env = dict(os.environ, **faketime.environment(speed, offset))
        sys.stdout.flush()
        os.execve(sys.executable, [sys.executable] + sys.argv, env)
    from obsw_sim.ditl_chain import ChainDay

    orbit_s = 86400.0 / pred.tle.mean_motion
    seconds = args.orbits * orbit_s if args.orbits else args.hours * 3600
    work = args.work or tempfile.mkdtemp(prefix="obsw-ditl-")
    down = args.down or (2_400_000 if args.orbits else 5_000_000)
    up = args.up or (600_000 if args.orbits else 1_000_000)
    day = ChainDay(
        work,
        pred,
        seconds,
        speed,
        out=print,
        down_size=down,
        up_size=up,
        downlink_bps=args.downlink,
        up_rate=args.up_rate,
    )
    began = time.monotonic()

    def progress(t, d):
        print("  %5.1f h: %d passes, %d reports down, backlog %s" % (
            t / 3600, d.contacts, sum(len(a) for a in d.archive.values()),
            d.backlog[-1][1] if d.backlog else "-"), flush=True)  # fmt: skip

    f = day.run(progress)
    took = (time.monotonic() - began) / speed  # the monotonic clock runs fast too
    results = checks(common(day, f), full=not args.orbits)
    for name, ok, detail in results:
        print("%s %s: %s" % ("ok  " if ok else "FAIL", name, detail))
    print("%.1f h of orbit in %.0f s here (%g times)" % (f["hours"], took, speed))
    if args.write:
        plot(day, f, os.path.join(ROOT, "docs", "ditl.png"))
        with open(os.path.join(ROOT, "docs", "ditl-last-run.md"), "w") as out:
            out.write(page(day, f, results, took, speed))
        print("wrote docs/ditl-last-run.md and docs/ditl.png")
    faketime.clean(os.getpid())
    bad = sum(1 for r in results if not r[1])
    print("%d passed, %d failed" % (len(results) - bad, bad))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
