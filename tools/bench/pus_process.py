"""Benchmark: TCs through the PUS application process over loopback UDP, with their reports.

The server runs in a child process: either the on-board PUS process (obsw) serving TC[17,1]
with all four reports requested (TM[1,1], TM[1,3], TM[17,2], TM[1,7]), or, as the
reference, a bare UDP echo that answers each TC with four datagrams of the same packet.
The client is the same for both: pre-packed TCs, a window of requests in flight, raw
datagrams counted. Rows: TCs per second (pipelined) and TC-to-completion latency p50/p99
(one request at a time).

    python tools/bench/pus_process.py [--quick] [--json]
"""

import argparse
import json
import os
import select
import socket
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path[:0] = [os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]

from obsw.pus.tc import PusTc  # noqa: E402

APID = 10
REPORTS = 4  # datagrams that answer one TC


def serve_obsw(port):
    from obsw_host.pus.onboard import Onboard
    from obsw_host.sample import SDB_PATH, load_sdb

    onboard = Onboard(load_sdb(SDB_PATH), port=port, period=0.1, max_tasks=64).start()
    print("ready", flush=True)
    onboard._thread.join()


def serve_echo(port):
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", port))
    print("ready", flush=True)
    while True:
        data, addr = sock.recvfrom(65536)
        for _ in range(REPORTS):
            sock.sendto(data, addr)


def start(kind):
    probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    probe.bind(("127.0.0.1", 0))
    port = probe.getsockname()[1]
    probe.close()
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path[:2]))
    proc = subprocess.Popen(
        [sys.executable, os.path.abspath(__file__), "--serve", kind, "--port", str(port)],
        stdout=subprocess.PIPE,
        env=env,
    )
    proc.stdout.readline()
    return proc, ("127.0.0.1", port)


def packets(n):
    return [PusTc(APID, 17, 1, b"", i & 0x3FFF, source_id=1).pack() for i in range(n)]


def client():
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 21)
    sock.bind(("127.0.0.1", 0))
    return sock


def _drain(sock, timeout):
    got = 0
    r, _, _ = select.select([sock], [], [], timeout)
    while r:
        sock.recv(65536)
        got += 1
        r, _, _ = select.select([sock], [], [], 0)
    return got


def throughput(target, tcs, window=16):
    """TCs per second with ``window`` requests in flight; every report is waited for."""
    sock = client()
    expected = len(tcs) * REPORTS
    got = 0
    sent = 0
    t0 = time.perf_counter()
    while got < expected:
        while sent < len(tcs) and sent - got // REPORTS < window:
            sock.sendto(tcs[sent], target)
            sent += 1
        n = _drain(sock, 2.0)
        if n == 0:
            raise RuntimeError("no answer: %d of %d reports" % (got, expected))
        got += n
    dt = time.perf_counter() - t0
    sock.close()
    return len(tcs) / dt


def latency(target, tcs):
    """Seconds from sending a TC to receiving its last (completion) report, one at a time."""
    sock = client()
    out = []
    for raw in tcs:
        t0 = time.perf_counter()
        sock.sendto(raw, target)
        got = 0
        while got < REPORTS:
            n = _drain(sock, 2.0)
            if n == 0:
                raise RuntimeError("no answer")
            got += n
        out.append(time.perf_counter() - t0)
    sock.close()
    out.sort()
    return out[len(out) // 2], out[min(len(out) - 1, int(len(out) * 0.99))]


def measure(kind, n_tp, n_lat, runs):
    proc, target = start(kind)
    try:
        throughput(target, packets(200))  # warm up
        tps, p50s, p99s = [], [], []
        for _ in range(runs):
            tps.append(throughput(target, packets(n_tp)))
            p50, p99 = latency(target, packets(n_lat))
            p50s.append(p50 * 1e6)
            p99s.append(p99 * 1e6)
        return statistics.median(tps), statistics.median(p50s), statistics.median(p99s)
    finally:
        proc.terminate()
        proc.wait(5)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="a smaller run (under a minute)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--serve", choices=("obsw", "echo"), help=argparse.SUPPRESS)
    p.add_argument("--port", type=int, help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    if args.serve:
        try:
            (serve_obsw if args.serve == "obsw" else serve_echo)(args.port)
        except KeyboardInterrupt:
            pass
        return 0
    n_tp, n_lat, runs = (1000, 300, 3) if args.quick else (5000, 1000, 5)
    ours = measure("obsw", n_tp, n_lat, runs)
    ref = measure("echo", n_tp, n_lat, runs)
    cases = (
        ("TC[17,1] with 4 reports, TCs per second", "TC/s", True),
        ("TC to completion report, p50", "us", False),
        ("TC to completion report, p99", "us", False),
    )
    rows = []
    for (case, unit, higher), a, b in zip(cases, ours, ref):
        rows.append(
            {
                "case": case,
                "impl": "obsw",
                "value": round(a, 1),
                "unit": unit,
                "higher_is_better": higher,
            }
        )
        rows.append(
            {
                "case": case,
                "impl": "reference",
                "value": round(b, 1),
                "unit": unit,
                "higher_is_better": higher,
            }
        )
    if args.json:
        print(json.dumps({"bench": "pus_process", "rows": rows}))
        return 0
    print(
        "%-44s %12s %12s %8s" % ("case (reference: bare UDP echo)", "obsw", "reference", "ratio")
    )
    for (case, unit, higher), a, b in zip(cases, ours, ref):
        ratio = a / b if higher else b / a
        print("%-44s %9.1f %-2s %9.1f %-2s %7.2fx" % (case, a, unit[:2], b, unit[:2], ratio))
    print("ratio: obsw relative to the reference (1.00x = as fast as a bare echo)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
