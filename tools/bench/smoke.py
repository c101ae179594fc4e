"""Every benchmark alive: each one in its quickest mode with --json, its figures checked.

    python tools/bench/smoke.py [NAME...] [--timeout SECONDS] [--jobs N]

Runs each benchmark of report.py's list (all when no NAME is given) as `report.py run --quick`
would, but saves nothing: it checks that the benchmark exited 0 and printed one JSON object in
the common format (`bench`, and `rows` of case, impl, a finite number as value, unit,
higher_is_better), with at least one row of obsw's. No timing is asserted: a slow benchmark
passes, a broken one fails. A benchmark that cannot run on this machine (Yamcs without Java,
the board without its toolchain) exits with SKIP (77) and a line saying why: counted as a
skip. Also fails when a script of tools/bench/ is neither a benchmark of the list nor a helper.
The last line is `N passed, N failed, N skipped`.
"""

import argparse
import concurrent.futures
import importlib.util
import json
import math
import os
import pathlib
import signal
import subprocess
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
# report.py by its file: this folder on sys.path would shadow the peers (its spacecan.py)
_spec = importlib.util.spec_from_file_location("bench_report", HERE / "report.py")
report = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(report)

SKIP = 77  # a benchmark's exit status when it cannot run here (its reason on stderr)
TIMEOUT = 600  # seconds for one quick run: under a minute when quiet, over 5 on a loaded machine


def problems(result, name):
    """What is wrong with a benchmark's JSON object (empty when nothing is)."""
    out = []
    if not isinstance(result, dict):
        return ["not a JSON object"]
    rows = result.get("rows")
    if not isinstance(result.get("bench"), str):
        out.append("no 'bench' name")
    if not isinstance(rows, list) or not rows:
        return out + ["no rows"]
    for i, row in enumerate(rows):
        missing = [
            k for k in ("case", "impl", "value", "unit", "higher_is_better") if k not in row
        ]
        if missing:
            out.append("row %d has no %s" % (i, ", ".join(missing)))
            continue
        v = row["value"]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            what = (i, row["case"], row["impl"], v)
            out.append("row %d (%s, %s): value %r is not a finite number" % what)
        if not isinstance(row["higher_is_better"], bool):
            out.append("row %d: higher_is_better is not true or false" % i)
    if not any(r.get("impl") == "obsw" for r in rows):
        out.append("no row of obsw's")
    return out


# a benchmark runs with SIGTERM as SystemExit, so that at a timeout its `finally` blocks and
# context managers stop what it started (QEMU, an OBC, Yamcs) and remove its temporary folders
_RUN = (
    "import os, runpy, signal, sys; "
    "signal.signal(signal.SIGTERM, lambda *a: sys.exit(143)); "
    "sys.argv = sys.argv[1:]; sys.path[0] = os.path.dirname(sys.argv[0]); "
    "runpy.run_path(sys.argv[0], run_name='__main__')"
)
GRACE = 20.0  # seconds a timed-out benchmark has to stop before its process group is killed


def _run(argv, env, timeout):
    """``subprocess.run`` in a process group of its own: at the timeout the whole group gets
    SIGTERM, then SIGKILL after GRACE, and TimeoutExpired is raised; nothing is left running."""
    proc = subprocess.Popen(
        argv,
        cwd=report.ROOT,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGTERM)
        try:
            proc.communicate(timeout=GRACE)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.communicate()
        raise
    return subprocess.CompletedProcess(argv, proc.returncode, out, err)


def smoke(name, timeout):
    """('passed' | 'failed' | 'skipped', seconds, detail) of one benchmark's quick run."""
    script, extra, _ = report.RUNS[name]
    argv = [sys.executable, "-c", _RUN, str(HERE / script), "--json", "--quick"]
    t0 = time.monotonic()
    try:
        res = _run(argv, dict(os.environ, **extra), timeout)
    except subprocess.TimeoutExpired:
        return "failed", time.monotonic() - t0, "no result in %d s" % timeout
    seconds = time.monotonic() - t0
    if res.returncode == SKIP:
        why = (res.stderr.strip().splitlines() or ["no reason given"])[-1]
        return "skipped", seconds, why
    if res.returncode != 0:
        return "failed", seconds, "exit %d\n%s" % (res.returncode, res.stderr[-2000:])
    lines = [line for line in res.stdout.splitlines() if line.startswith("{")]
    if not lines:
        return "failed", seconds, "no JSON object on stdout\n%s" % res.stderr[-2000:]
    try:
        result = json.loads(lines[-1])
    except ValueError as e:
        return "failed", seconds, "its JSON does not parse: %s" % e
    bad = problems(result, name)
    if bad:
        return "failed", seconds, "; ".join(bad)
    return "passed", seconds, "%d rows" % len(result["rows"])


def unlisted():
    """Scripts of tools/bench/ that are neither in report.py's list nor helpers."""
    listed = {script for script, _, _ in report.RUNS.values()}
    return sorted(
        p.name for p in HERE.glob("*.py") if p.name not in listed and p.name not in report.HELPERS
    )


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("names", nargs="*", metavar="NAME", help="of: " + ", ".join(report.RUNS))
    ap.add_argument("--timeout", type=float, default=TIMEOUT, help="seconds per benchmark")
    ap.add_argument("--jobs", type=int, default=1, help="benchmarks run at once (default 1)")
    args = ap.parse_args(argv)
    unknown = [n for n in args.names if n not in report.RUNS]
    if unknown:
        ap.error("unknown benchmark %s; expected some of %s" % (unknown, ", ".join(report.RUNS)))
    counts = {"passed": 0, "failed": 0, "skipped": 0}
    t0 = time.monotonic()
    for script in unlisted():
        print("FAIL tools/bench/%s: not in report.py's RUNS nor a helper" % script)
        counts["failed"] += 1
    names = args.names or list(report.RUNS)
    with concurrent.futures.ThreadPoolExecutor(max(1, args.jobs)) as pool:
        runs = {name: pool.submit(smoke, name, args.timeout) for name in names}
        for name in names:  # in the list's order, each as soon as it and those before are done
            outcome, seconds, detail = runs[name].result()
            counts[outcome] += 1
            mark = {"passed": "ok  ", "failed": "FAIL", "skipped": "skip"}[outcome]
            print("%s %-14s %6.1f s  %s" % (mark, name, seconds, detail), flush=True)
    print("(%.0f s in all)" % (time.monotonic() - t0))
    print("%(passed)d passed, %(failed)d failed, %(skipped)d skipped" % counts)
    return 1 if counts["failed"] else 0


if __name__ == "__main__":
    sys.exit(main())
