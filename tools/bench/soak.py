"""Soak: the OBC and its processes for hours, their memory sampled, with traffic and idle phases.

`obsw obc serve` of the sample spacecraft (a state folder and free ports of its own) runs for
--minutes (default 120; --quick: 1). The resident memory (RSS, /proc) of the platform manager
and of each process it started is sampled every --sample seconds (default 10). Phases
alternate, traffic first, each --phase long (default 10 minutes):

  traffic   a ping (TC[17,1]) every 0.2 s; a one-shot housekeeping report (TC[3,27]) and a
            parameter report (TC[20,1]) every 5 s; a 20 kB class 2 CFDP put to the OBC every
            minute (`obsw cfdp put`, the same file name each time)
  idle      nothing from the ground: the OBC's own periodic work goes on

The first --warmup (default 10 minutes) is not counted: caches, pools and bounded buffers fill.
The figure is the growth after it, in kB per hour: the least-squares slope of the OBC's summed
RSS over the samples after warm-up (each process's too), next to the goal (100 kB per hour,
issue 41). With --trace the processes also trace their Python allocations (tracemalloc): the
slope of the memory they trace, recorded by each process every sample period, is given too (it
sees a Python leak that a heap's free space would hide from RSS for a while), and so is the
RSS growth without that of tracemalloc's own tables (they keep every call path they have seen:
the tracer's memory, not the OBC's); the goal is then met when both the latter and the Python
heap's growth are within it, and a snapshot of each process at the end of warm-up and at the
end names the source lines that grew most. The tracer changes what it measures (below), so the
figure is the run without it and the traced run is the diagnosis. Slopes over short runs
(--quick) say little: the first hours are what count.

What it found: under traffic the PUS process's resident memory grew while its Python heap
did not. The memory was glibc's, in the malloc arena of the thread that runs the PUS loop:
its interaction-layer and CFDP sockets received each message into a fresh 64-70 kB buffer,
which CPython then shrank to what came; the small message left where the buffer began kept
the space after it from being reused whole, and the arena grew by what it could not reuse
(malloc_stats: 450 kB held for 164 kB in use after 10 minutes). Each socket now reads into
one buffer of its own and copies what came at its size (tests/host/test_receive_buffers.py).

Two 2-hour runs of that code (commit 66df7bc, 130 minutes each, side by side, 2 hours counted,
721 samples, about 20,700 pings, 824 report requests and 70 CFDP puts each, no restart) tell the
OBC from its tracer. Without tracemalloc (the OBC as it flies: the figures below; the tool then
took --no-trace, now the default) the OBC's RSS grew 22.5 kB per hour (the PUS process 7.9, the
platform manager 14.7): the goal met. With it (--trace; its output, with the growers it names,
is docs/benchmarks/soak-traced.json) the Python heap grew 23.3 kB per hour, and tracemalloc's
own tables 11.1, but the RSS without those tables grew 235.6. Same code, same traffic, same
hours: that growth comes with the tracer (most likely its record for every traced block,
allocated among the OBC's own, keeps glibc's arenas from reusing what the OBC frees; not
measured further).

Usage: python tools/bench/soak.py [--minutes M] [--quick] [--trace] [--json]
"""

import argparse
import glob
import json
import os
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path[:0] = [os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]

from measure import row  # noqa: E402
from obsw_host.il.processes import python_path  # noqa: E402
from obsw_host.obc import memtrace  # noqa: E402
from obsw_host.sample import MISSION_DIR  # noqa: E402

GOAL = 100.0  # kB per hour after warm-up (issue 41)
# the mission's platform settings for the run: on a shared machine a loaded process can miss
# the sample's 3 s heartbeat deadline, and a process restarted starts its memory afresh
PLATFORM = {"deadline": 30.0, "start_timeout": 120.0}
PING_EVERY = 0.2
REPORTS_EVERY = 5.0
PUT_EVERY = 60.0
PUT_SIZE = 20000
TOP = 8  # growers named per process


def rss_kb(pid):
    try:
        with open("/proc/%d/status" % pid) as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return None


def children(pid):
    """Every descendant of ``pid`` (Linux /proc)."""
    out = []
    try:
        for task in os.listdir("/proc/%d/task" % pid):
            with open("/proc/%d/task/%s/children" % (pid, task)) as f:
                out += [int(x) for x in f.read().split()]
    except OSError:
        return []
    for c in list(out):
        out += children(c)
    return out


def mission_copy(folder):
    """The sample mission copied to ``folder`` with the run's platform settings (PLATFORM)."""
    shutil.copytree(MISSION_DIR, folder)
    path = os.path.join(folder, "mission.json")
    with open(path) as f:
        mission = json.load(f)
    mission.pop("$schema", None)  # a path relative to the sample's place
    mission.setdefault("platform", {}).update(PLATFORM)
    with open(path, "w") as f:
        json.dump(mission, f, indent=2)
    return folder


def process_name(pid):
    """The OBC process a pid runs (its --process argument), or 'platform'."""
    try:
        with open("/proc/%d/cmdline" % pid) as f:
            argv = f.read().split("\0")
    except OSError:
        return None
    if "--process" in argv:
        return argv[argv.index("--process") + 1]
    return "platform"


def slope_per_hour(points):
    """Least-squares slope of [(seconds, value)] in value per hour (None below 3 points)."""
    if len(points) < 3:
        return None
    ts = [t for t, _ in points]
    vs = [v for _, v in points]
    mt, mv = statistics.fmean(ts), statistics.fmean(vs)
    den = sum((t - mt) ** 2 for t in ts)
    if den == 0:
        return None
    return 3600.0 * sum((t - mt) * (v - mv) for t, v in zip(ts, vs)) / den


class Soak:
    def __init__(self, work, trace, sample, out=print):
        from obsw_host.mission.new import free_fleet_base

        self.work = work
        self.out = out
        self.trace = trace
        self.sample = sample
        self.snaps = os.path.join(work, "snaps")
        self.ground_root = os.path.join(work, "ground")
        os.makedirs(self.ground_root)
        self.env = dict(
            os.environ, PYTHONPATH=python_path(), OBSW_PORT_BASE=str(free_fleet_base(1))
        )
        self.env.pop("PYTHONDONTWRITEBYTECODE", None)  # as installed: with bytecode
        if trace:
            self.env[memtrace.ENV] = self.snaps
            self.env[memtrace.ENV + "_PERIOD"] = str(sample)
        os.environ["OBSW_PORT_BASE"] = self.env["OBSW_PORT_BASE"]  # our ground's ports too
        from obsw_host.mission.ids import MissionIds

        self.mission = mission_copy(os.path.join(work, "mission"))
        self.ids = MissionIds.locate(self.mission)
        self.address = (self.ids.config.host, self.ids.ports.pus)
        self.apid = self.ids.pus_apid
        self.proc = None
        self.ground = None
        self.counts = {"pings": 0, "answered": 0, "reports": 0, "puts": 0, "puts_ok": 0}
        self.samples = []  # (seconds, {name: kB})
        self.seen = {}  # process name -> the pids it had (more than one: restarted)

    # -------------------------------------------------------------------------- the OBC

    def start(self):
        state = os.path.join(self.work, "state")
        cmd = [sys.executable, "-m", "obsw_host.obc", self.mission, "--state", state, "--quiet"]
        self.log = open(os.path.join(self.work, "obc.log"), "w")
        self.proc = subprocess.Popen(
            cmd, env=self.env, stdin=subprocess.DEVNULL, stdout=self.log, stderr=self.log
        )
        from obsw_host.pus.ground import Ground

        ids = self.ids
        self.ground = Ground(ids.sdb, apid=self.apid, target=self.address, timeout=2.0,
                             source_id=ids.source_id, config=ids.pus_config)  # fmt: skip
        end = time.monotonic() + 180
        while time.monotonic() < end:
            if self.proc.poll() is not None:
                raise RuntimeError("the OBC ended with status %s" % self.proc.returncode)
            if self.ping(0.1):
                return
        raise RuntimeError("the OBC did not answer a ping within 180 s")

    def stop(self):
        if self.ground is not None:
            self.ground.close()
        if self.proc is not None and self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(20)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(10)
        if getattr(self, "log", None):
            self.log.close()

    def pids(self):
        root = self.proc.pid
        return {pid: process_name(pid) for pid in [root] + children(root)}

    def memory(self):
        """{process name: RSS kB} now (a process restarted under the same name adds up)."""
        out = {}
        for pid, name in self.pids().items():
            kb = rss_kb(pid)
            if name and kb is not None:
                out[name] = out.get(name, 0) + kb
                self.seen.setdefault(name, set()).add(pid)
        return out

    def snapshot(self):
        """Each traced process dumps a tracemalloc snapshot; waits until all are written."""
        if not self.trace:
            return
        before = set(glob.glob(os.path.join(self.snaps, "*.snap")))
        pids = list(self.pids())
        for pid in pids:
            try:
                os.kill(pid, signal.SIGUSR2)
            except ProcessLookupError:
                pass
        end = time.monotonic() + 60
        while time.monotonic() < end:
            new = set(glob.glob(os.path.join(self.snaps, "*.snap"))) - before
            if len(new) >= len(pids):
                return
            time.sleep(0.2)

    # -------------------------------------------------------------------------- traffic

    def ping(self, timeout=0.5):
        self.counts["pings"] += 1
        try:
            ok = self.ground.ping(timeout=timeout).ok
        except Exception:  # a timeout: counted, not fatal
            ok = False
        self.counts["answered"] += bool(ok)
        return ok

    def reports(self):
        sdb = self.ids.sdb
        self.counts["reports"] += 1
        try:
            if sdb.housekeeping:
                self.ground.housekeeping(sdb.housekeeping[0]["sid"], timeout=2.0)
            self.ground.get_parameters(*sorted(sdb.parameters)[:4], timeout=2.0)
        except Exception:
            pass

    def put(self):
        name = "soak.bin"
        with open(os.path.join(self.ground_root, name), "wb") as f:
            f.write(os.urandom(PUT_SIZE))
        cmd = [sys.executable, "-m", "obsw_host.cli", "cfdp", "put", "--mission", self.mission]
        cmd += [name, name, "--root", self.ground_root, "--class", "2", "--timeout", "40"]
        self.counts["puts"] += 1
        res = subprocess.run(cmd, env=self.env, capture_output=True, text=True, timeout=120)
        self.counts["puts_ok"] += res.returncode == 0
        if res.returncode != 0 and self.counts["puts"] - self.counts["puts_ok"] == 1:
            self.out("a CFDP put failed (reported once): %s" % res.stderr.strip()[-300:])

    # -------------------------------------------------------------------------- the run

    def run(self, minutes, warmup, phase, out):
        self.start()
        t0 = time.monotonic()
        end = t0 + 60 * minutes
        next_sample = t0
        next_reports = next_put = next_ping = t0
        warm = False
        while True:
            now = time.monotonic()
            if now >= end:
                break
            if not warm and now - t0 >= 60 * warmup:
                self.snapshot()  # the first snapshot, then the samples that count
                warm = True
                self.t_warm = time.monotonic() - t0
                self.wall_warm = time.time()
                next_sample = time.monotonic()
                out("warm-up over at %.0f s" % self.t_warm)
                continue
            if now >= next_sample:
                self.samples.append((now - t0, self.memory()))
                next_sample += self.sample
            traffic = int((now - t0) // (60 * phase)) % 2 == 0
            if traffic:
                if now < next_ping:
                    time.sleep(max(0.0, min(next_ping, next_sample) - now))
                    continue
                self.ping(1.0)
                next_ping = max(next_ping + PING_EVERY, time.monotonic())
                if now >= next_reports:
                    self.reports()
                    next_reports = now + REPORTS_EVERY
                if now >= next_put:
                    self.put()
                    next_put = time.monotonic() + PUT_EVERY
            else:
                time.sleep(min(1.0, max(0.0, next_sample - now)))
                next_reports = next_put = time.monotonic()
        self.samples.append((time.monotonic() - t0, self.memory()))
        self.snapshot()
        if not warm:
            self.t_warm = 0.0

    def traced(self):
        """{process name: [(unix time, bytes traced, tracemalloc's own bytes)]}, as each
        process recorded them."""
        out = {}
        for path in glob.glob(os.path.join(self.snaps, "*.traced")):
            name = os.path.basename(path).rsplit("-", 1)[0]
            with open(path) as f:
                for line in f:  # the last line may be half written: it is left out
                    fields = line.split()
                    if len(fields) == 3 and line.endswith("\n"):
                        t, traced, own = float(fields[0]), int(fields[1]), int(fields[2])
                        out.setdefault(name, []).append((t, traced, own))
        return out

    def growers(self):
        """{process name: [(bytes, blocks, where)]} between its first and last snapshot."""
        out = {}
        by = {}
        for path in glob.glob(os.path.join(self.snaps, "*.snap")):
            base = os.path.basename(path)[: -len(".snap")]
            name_pid, n = base.rsplit("-", 1)
            by.setdefault(name_pid, []).append((int(n), path))
        for name_pid, snaps in by.items():
            if len(snaps) >= 2:
                snaps.sort()
                name = name_pid.rsplit("-", 1)[0]
                out[name] = memtrace.growers(snaps[0][1], snaps[-1][1], TOP)
        return out


def analyse(soak):
    after = [(t, m) for t, m in soak.samples if t >= soak.t_warm]
    names = sorted({n for _, m in after for n in m})
    total = [(t, sum(m.values()) / 1.0) for t, m in after]
    res = {
        "total": slope_per_hour(total),
        "processes": {n: slope_per_hour([(t, m[n]) for t, m in after if n in m]) for n in names},
        "rss_start": total[0][1] if total else None,
        "rss_end": total[-1][1] if total else None,
        "samples": len(after),
        "traced": None,
        "traced_processes": {},
        "tracer": None,
        "held": None,
    }
    if soak.trace:
        traced = soak.traced()
        wall_warm = getattr(soak, "wall_warm", 0.0)
        own = {}
        for name, points in traced.items():
            pts = [(t, b / 1024.0) for t, b, _ in points if t >= wall_warm]
            res["traced_processes"][name] = slope_per_hour(pts)
            own[name] = slope_per_hour([(t, o / 1024.0) for t, _, o in points if t >= wall_warm])
        slopes = list(res["traced_processes"].values())
        # the slope of a sum is the sum of the slopes (each process samples on its own clock)
        res["traced"] = sum(slopes) if slopes and None not in slopes else None
        if res["total"] is not None and own and None not in own.values():
            # what the processes hold: RSS without the growth of tracemalloc's own tables
            res["tracer"] = sum(own.values())
            res["held"] = res["total"] - res["tracer"]
    return res


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--minutes", type=float, help="how long (default 120; --quick 1)")
    ap.add_argument("--warmup", type=float, help="minutes not counted (default 10; quick 0.3)")
    ap.add_argument("--phase", type=float, help="minutes of each phase (default 10; quick 0.2)")
    ap.add_argument("--sample", type=float, help="seconds between samples (default 10; quick 3)")
    ap.add_argument("--quick", action="store_true", help="1 minute: proves it runs")
    ap.add_argument("--trace", action="store_true", help="tracemalloc in the processes")
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    args = ap.parse_args(argv)
    q = args.quick
    minutes = args.minutes or (1.0 if q else 120.0)
    warmup = args.warmup if args.warmup is not None else (0.3 if q else min(10.0, minutes / 4))
    phase = args.phase or (0.2 if q else 10.0)
    sample = args.sample or (3.0 if q else 10.0)
    out = (lambda s: print(s, file=sys.stderr, flush=True)) if args.json else print
    # stopped early (SIGTERM): the OBC is stopped and the folder removed all the same
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(1))
    work = tempfile.mkdtemp(prefix="obsw-soak-")
    soak = Soak(work, args.trace, sample, out)
    try:
        soak.run(minutes, warmup, phase, out)
        res = analyse(soak)
        growers = soak.growers() if soak.trace else {}
    finally:
        soak.stop()
        shutil.rmtree(work, ignore_errors=True)
    # the goal: the memory the processes hold, RSS without tracemalloc's own when they are
    # traced (it keeps every call path it has seen), and their Python heap
    rss = res["held"] if res["held"] is not None else res["total"]
    figures = [rss] + ([res["traced"]] if res["traced"] is not None else [])
    met = all(f is not None and f <= GOAL for f in figures)
    hours = (minutes - warmup) / 60.0
    case = "OBC memory growth after warm-up (RSS, all processes)"
    rows = [
        _row(case, "obsw", res["total"]),
        _row(case, "reference", GOAL),
    ]
    for name, v in sorted(res["processes"].items()):
        rows.append(_row("RSS growth after warm-up, process %s" % name, "obsw", v))
    if res["held"] is not None:
        case = "OBC memory growth after warm-up (RSS without tracemalloc's own tables)"
        rows += [_row(case, "obsw", res["held"]), _row(case, "reference", GOAL)]
        rows.append(_row("tracemalloc's own tables, growth after warm-up", "obsw", res["tracer"]))
    if res["traced"] is not None:
        case = "Python heap growth after warm-up (tracemalloc, all processes)"
        rows += [_row(case, "obsw", res["traced"]), _row(case, "reference", GOAL)]
        for name, v in sorted(res["traced_processes"].items()):
            rows.append(_row("Python heap growth after warm-up, process %s" % name, "obsw", v))
    rows.append(
        {
            "case": "OBC RSS at the end of the run (all processes)",
            "impl": "obsw",
            "value": round((res["rss_end"] or 0) / 1024.0, 1),
            "unit": "MB",
            "higher_is_better": False,
        }
    )
    notes = [
        "%.1f minutes (%.1f of warm-up, then %.2f h counted, %d samples), phases of %.1f "
        "minutes; %d pings (%d answered), %d report requests, %d CFDP puts (%d delivered)"
        % (
            minutes,
            warmup,
            hours,
            res["samples"],
            phase,
            soak.counts["pings"],
            soak.counts["answered"],
            soak.counts["reports"],
            soak.counts["puts"],
            soak.counts["puts_ok"],
        ),  # fmt: skip
        "the goal of at most %g kB per hour after warm-up: %s"
        % (GOAL, "met" if met else "MISSED"),
    ]
    restarted = sorted(n for n, pids in soak.seen.items() if len(pids) > 1)
    notes.append(
        "processes restarted during the run (their figure spans several processes): %s"
        % ", ".join(restarted)
        if restarted
        else "no process restarted during the run"
    )
    if not met:
        for name, top in sorted(growers.items()):
            if top:
                notes.append(
                    "top growers of process %s: %s"
                    % (name, "; ".join("%s %+d B (%+d blocks)" % (w, b, n) for b, n, w in top))
                )
    if args.json:
        print(json.dumps({"bench": "soak", "rows": rows, "notes": notes, "met": met}))
        return 0
    print("%-66s %12s" % ("case", "kB/h"))
    for r in rows:
        if r["impl"] == "obsw" and r["value"] is not None:
            print("%-66s %12.1f %s" % (r["case"], r["value"], r["unit"]))
    for note in notes:
        print(note)
    return 0


def _row(case, impl, value):
    return row(case, impl, None if value is None else round(value, 1), "kB per hour", False)


if __name__ == "__main__":
    sys.exit(main())
