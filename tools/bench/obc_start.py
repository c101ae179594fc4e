"""Benchmark of start-up: the OBC's cold start to its first answered PUS ping, with and without
bytecode, and the whole `obsw ground ping` command against an empty Python start.

Each cold-start run starts the platform manager of a mission (default: the sample spacecraft)
in a fresh state folder, as `obsw obc serve` does, and sends TC[17,1] to the PUS process every
10 ms until TM[17,2] comes back; the figure is the time from the start of the command to that
reply. The process is then stopped with SIGTERM. There is no peer for this figure: the
reference row is the goal (1 s). The median of the runs is printed with their spread.

  with bytecode     the OBC as installed, its modules compiled to bytecode (pip compiles them
                    at install): the bytecode goes to a cache folder of this run
                    ($PYTHONPYCACHEPREFIX), written by a first run that is not counted,
                    whatever $PYTHONDONTWRITEBYTECODE says in the caller's environment
  without bytecode  every module compiled from source at every start: an empty cache folder
                    and $PYTHONDONTWRITEBYTECODE=1 (a source tree or an install that could not
                    write its bytecode)

`obsw ground ping` (with bytecode) runs against the OBC of the last cold start, in pairs back to
back with `python -c pass` (the interpreter's own start, the reference): the ratio is the
median of the pairs' ratios (goal: within 6 times). The two cold-start variants alternate too.

Usage: python tools/bench/obc_start.py [MISSION] [--runs N] [--quick] [--json]
"""

import argparse
import json
import os
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path[:0] = [os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]

from measure import row  # noqa: E402
from obsw.pus.tc import PusTc  # noqa: E402
from obsw.pus.tm import PusTm  # noqa: E402
from obsw_host.il.processes import python_path  # noqa: E402
from obsw_host.mission.config import load as load_config  # noqa: E402
from obsw_host.obc.topology import Topology  # noqa: E402
from obsw_host.sample import MISSION_DIR  # noqa: E402

GOAL = 1.0  # seconds: issue 23's goal for the cold start
LIMIT = 60.0  # a run that has not answered by then has failed


def pus_address(mission):
    """Where the mission's PUS process takes TCs, and its APID."""
    topology = Topology(load_config(mission))
    return (topology.config.host, topology.pus_port()), topology.pus_apid()


PING_GOAL = 6.0  # `obsw ground ping` within 6 times `python -c pass` (issue 41)


def start_env(pycache, bytecode=True):
    """The environment of a start: bytecode in ``pycache``, or none written or read."""
    env = dict(os.environ, PYTHONPATH=python_path(), PYTHONPYCACHEPREFIX=pycache)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    if not bytecode:
        env["PYTHONDONTWRITEBYTECODE"] = "1"
    return env


def one_run(mission, address, apid, pycache, bytecode=True, then=None):
    """Seconds from the start of `obsw obc serve` to the first TM[17,2]; ``then()`` runs
    while the OBC still serves."""
    state = tempfile.mkdtemp(prefix="obsw-start-")
    env = start_env(pycache, bytecode)
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind((address[0], 0))
    sock.settimeout(0.01)
    ping = PusTc(apid, 17, 1).pack()
    cmd = [sys.executable, "-m", "obsw_host.obc", "--state", state, "--quiet"]
    cmd += [mission] if mission else []
    quiet = subprocess.DEVNULL
    t0 = time.perf_counter()
    proc = subprocess.Popen(
        cmd, env=env, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=quiet
    )
    try:
        while time.perf_counter() - t0 < LIMIT:
            if proc.poll() is not None:
                raise RuntimeError("the OBC ended with status %s" % proc.returncode)
            sock.sendto(ping, address)
            try:
                while True:
                    raw = sock.recv(65536)
                    tm = PusTm.unpack(raw)
                    if (tm.service, tm.subtype) == (17, 2):
                        took = time.perf_counter() - t0
                        if then is not None:
                            then()
                        return took
            except (socket.timeout, ConnectionRefusedError):
                continue
            except ValueError:
                continue
        raise RuntimeError("no answer to a ping within %.0f s" % LIMIT)
    finally:
        sock.close()
        proc.terminate()
        try:
            proc.wait(20)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(10)
        shutil.rmtree(state, ignore_errors=True)


def timed(cmd, env):
    t0 = time.perf_counter()
    res = subprocess.run(cmd, env=env, stdin=subprocess.DEVNULL, capture_output=True)
    took = time.perf_counter() - t0
    if res.returncode != 0:
        raise RuntimeError("%s: status %d\n%s" % (" ".join(cmd), res.returncode, res.stderr))
    return took


def ping_pairs(mission, pycache, pairs):
    """[(`python -c pass` s, `obsw ground ping` s)] run back to back, with bytecode."""
    env = start_env(pycache)
    ping = [sys.executable, "-m", "obsw_host.cli", "ground", "--mission", mission, "ping"]
    timed(ping, env)  # compiles the ground's bytecode: not counted
    return [(timed([sys.executable, "-c", "pass"], env), timed(ping, env)) for _ in range(pairs)]


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument(
        "mission", nargs="?", help="mission folder or file (default: the sample spacecraft)"
    )
    p.add_argument("--runs", type=int, default=5, help="runs (default 5)")
    p.add_argument("--quick", action="store_true", help="3 runs, 5 ping pairs")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    args = p.parse_args(argv)
    args.mission = args.mission or MISSION_DIR  # named: the OBC uses no mission by default
    runs = 3 if args.quick else args.runs
    address, apid = pus_address(args.mission)
    pycache = tempfile.mkdtemp(prefix="obsw-start-pycache-")
    empty = tempfile.mkdtemp(prefix="obsw-start-nocache-")
    pairs = []
    try:
        one_run(args.mission, address, apid, pycache)  # compiles the bytecode: not counted
        times = {"with bytecode": [], "without bytecode": []}
        for i in range(runs):
            for bytecode in (True, False) if i % 2 == 0 else (False, True):
                then = None
                if bytecode and i == runs - 1:  # while this OBC serves: the ground's start

                    def then():
                        pairs.extend(ping_pairs(args.mission, pycache, 5 if args.quick else 15))

                took = one_run(args.mission, address, apid, pycache if bytecode else empty,
                               bytecode, then)  # fmt: skip
                times["with bytecode" if bytecode else "without bytecode"].append(took)
    finally:
        shutil.rmtree(pycache, ignore_errors=True)
        shutil.rmtree(empty, ignore_errors=True)
    bare = statistics.median(p for p, _ in pairs)
    ping = statistics.median(g for _, g in pairs)
    ping_ratio = statistics.median(g / p for p, g in pairs)
    rows = []
    for what, values in times.items():
        case = "cold start to first ping, %s" % what
        rows.append(_row(case, "obsw", statistics.median(values), runs=values))
        rows.append(_row(case, "reference", GOAL))
    case = "`obsw ground ping`, whole command (reference: `python -c pass`)"
    rows.append(
        _row(case, "obsw", ping, ratio=round(1 / ping_ratio, 4), runs=[g for _, g in pairs])
    )
    rows.append(_row(case, "reference", bare, runs=[p for p, _ in pairs]))
    if args.json:
        print(json.dumps({"bench": "obc_start", "rows": rows, "notes": [_ping_note(ping_ratio)]}))
        return 0
    print("start-up, %d runs each; `obsw ground ping`: %d pairs" % (runs, len(pairs)))
    print("%-44s %8s %8s %8s  %s" % ("case", "obsw", "goal", "ratio", "spread"))
    for what, values in times.items():
        m = statistics.median(values)
        line = ("cold start to first ping, " + what, m, GOAL, m / GOAL, min(values), max(values))
        print("%-44s %7.2fs %7.2fs %7.2fx  %.2f-%.2f s" % line)
    print("%-44s %7.3fs %7.3fs %7.2fx  (python -c pass; median of the pairs' ratios)" % (
        "obsw ground ping", ping, bare, ping_ratio))  # fmt: skip
    print(_ping_note(ping_ratio))
    return 0


def _row(case, impl, value, **extra):
    return row(case, impl, value, "s", False, **extra)


def _ping_note(ratio):
    return (
        "`obsw ground ping` took %.1f times `python -c pass` (median of the pairs; goal %g): %s"
        % (ratio, PING_GOAL, "met" if ratio <= PING_GOAL else "MISSED")
    )


if __name__ == "__main__":
    sys.exit(main())
