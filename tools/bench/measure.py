"""What every benchmark of tools/bench measures with: one way to time a call, to take a median,
to start an obsw process and stop it, and to write a row of the common format.

    from measure import rate, median_of, row   # beside the benchmark scripts
"""

import os
import statistics
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tests", "host"))

from mission_ports import free_port, stop  # noqa: E402, F401 (the tests' own, for the benchmarks)


def rate(fn, seconds, repeats):
    """Median calls per second of ``fn`` over ``repeats`` runs of about ``seconds`` each
    (one call first, outside the count)."""
    fn()
    results = []
    for _ in range(repeats):
        n = 0
        t0 = time.perf_counter()
        while True:
            fn()
            n += 1
            dt = time.perf_counter() - t0
            if dt >= seconds:
                break
        results.append(n / dt)
    return statistics.median(results)


def batch_size(run, seconds, start=10, most=1 << 22):
    """How many calls ``run(n)`` makes in about ``seconds`` (from ``start``, at most ``most``
    tried)."""
    n = start
    while True:
        t0 = time.perf_counter()
        run(n)
        dt = time.perf_counter() - t0
        if dt >= seconds / 4 or n >= most:
            break
        n *= 4
    return max(1, int(n * seconds / dt))


def median_of(fn, runs):
    """The median of ``runs`` results of ``fn()``."""
    return statistics.median([fn() for _ in range(runs)])


def row(case, impl, value, unit, higher_is_better, **extra):
    """One row of a benchmark's JSON object (tools/bench/report.py reads them)."""
    out = {"case": case, "impl": impl, "value": value, "unit": unit,
           "higher_is_better": higher_is_better}  # fmt: skip
    out.update(extra)
    return out


def child_env():
    """The environment of an obsw process started from the source tree."""
    path = os.pathsep.join([os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")])
    return dict(os.environ, PYTHONPATH=path)
