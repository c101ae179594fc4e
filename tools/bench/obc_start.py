"""Benchmark of the OBC's cold start: `obsw obc serve` started to its first answered PUS ping.

Each run starts the platform manager of a mission (default: the sample spacecraft) in a fresh
state folder, as `obsw obc serve` does, and sends TC[17,1] to the PUS process every 10 ms until
TM[17,2] comes back; the figure is the time from the start of the command to that reply. The
process is then stopped with SIGTERM. There is no peer for this figure: the reference row is
the goal (1 s). The median of the runs is printed with their spread (fastest, slowest).

The OBC runs as installed, with its modules compiled to bytecode (pip compiles them at
install): the bytecode goes to a cache folder of this run ($PYTHONPYCACHEPREFIX), written by a
first run that is not counted, whatever $PYTHONDONTWRITEBYTECODE says in the caller's
environment (with it, every process would compile every module at every start).

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


def one_run(mission, address, apid, pycache):
    """Seconds from the start of `obsw obc serve` to the first TM[17,2]."""
    state = tempfile.mkdtemp(prefix="obsw-start-")
    env = dict(os.environ, PYTHONPATH=python_path(), PYTHONPYCACHEPREFIX=pycache)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
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
                        return time.perf_counter() - t0
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


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument(
        "mission", nargs="?", help="mission folder or file (default: the sample spacecraft)"
    )
    p.add_argument("--runs", type=int, default=5, help="runs (default 5)")
    p.add_argument("--quick", action="store_true", help="3 runs")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    args = p.parse_args(argv)
    args.mission = args.mission or MISSION_DIR  # named: the OBC uses no mission by default
    runs = 3 if args.quick else args.runs
    address, apid = pus_address(args.mission)
    pycache = tempfile.mkdtemp(prefix="obsw-start-pycache-")
    try:
        one_run(args.mission, address, apid, pycache)  # compiles the bytecode: not counted
        times = [one_run(args.mission, address, apid, pycache) for _ in range(runs)]
    finally:
        shutil.rmtree(pycache, ignore_errors=True)
    median = statistics.median(times)
    if args.json:
        rows = [
            {
                "case": "cold start to first ping",
                "impl": "obsw",
                "value": median,
                "unit": "s",
                "higher_is_better": False,
                "runs": times,
            },  # fmt: skip
            {
                "case": "cold start to first ping",
                "impl": "reference",
                "value": GOAL,
                "unit": "s",
                "higher_is_better": False,
            },  # fmt: skip
        ]
        print(json.dumps({"bench": "obc_start", "rows": rows}))
        return 0
    print("OBC cold start (obsw obc serve) to the first answered ping, %d runs" % runs)
    print("%-28s %8s %8s %8s %7s" % ("case", "obsw", "goal", "ratio", "spread"))
    spread = (min(times), max(times))
    print("%-28s %7.2fs %7.2fs %7.2fx  %.2f-%.2f s" % (
        "cold start to first ping", median, GOAL, median / GOAL, *spread))  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
