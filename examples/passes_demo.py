"""Demo: operations across passes. The sample spacecraft's orbit (its TLE) over its ground
station: the passes of the next day with what each can carry, the onboard pass table they make
(the argument of TC[8,1] Passes.load, what `obsw ops uplink` sends), the pass plan as service
11 commands, then two orbits flown on one injected clock: housekeeping stored out of contact and
dumped by priority at AOS, a 2 MB file down and a 500 kB file up, each across two passes,
suspended at LOS and resumed where it stopped."""

from obsw_host.mission.check import load
from obsw_host.ops.pass_table import table, windows
from obsw_host.ops.passes import from_mission
from obsw_host.ops.plan import plan
from obsw_host.sample import MISSION_DIR
from obsw_sim.ditl import Day


def run(out=print):
    pred = from_mission(load(MISSION_DIR).config.doc)
    t0 = pred.tle.epoch.timestamp()
    passes = pred.passes(t0, t0 + 86400)
    out("the next day from the TLE's epoch: %d passes" % len(passes))
    for p in passes:
        d = p.to_dict()
        row = (d["station"], d["aos"], d["los"], d["max_elevation"], d["downlink_octets"])
        out("  %s  AOS %s  LOS %s  %5.1f deg  %7d octets down" % row)
    ws = windows(passes)
    out("  pass table for Passes.load: %d windows, %d octets (AOS, LOS: uint32 onboard seconds)"
        % (len(ws), len(table(passes))))  # fmt: skip
    for s in plan(passes[:1]):
        out("  planned: %s" % s)
    start = passes[0].aos - 3600.0
    day = Day(pred, start, 2 * 86400.0 / pred.tle.mean_motion, down_file=2_000_000,
              up_file=500_000)  # fmt: skip
    f = day.run()
    out("two orbits: %d passes, housekeeping %d generated, %d delivered (%d due), %d twice"
        % (f["passes"], sum(f["generated"].values()), sum(f["delivered"].values()),
           sum(f["due"].values()), f["duplicates"]))  # fmt: skip
    out("file down identical: %s (received at the second AOS: %s octets); file up identical: %s"
        % (f["down_file"], [p for _t, p in f["down_resumes"]], f["up_file"]))  # fmt: skip
    out("planned commands executed: %d of %d, latest %.3f s after its time"
        % (f["executed"], f["planned"], f["max_lateness"]))  # fmt: skip
    ok = f["missing"] == 0 and f["duplicates"] == 0 and f["down_file"] and f["up_file"]
    if not ok:
        raise RuntimeError("the two orbits did not deliver everything exactly once")
    return 0


if __name__ == "__main__":
    run()
