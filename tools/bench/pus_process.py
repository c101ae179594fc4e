"""Benchmark: TCs through the PUS application process over loopback UDP, with their reports.

Three servers run in child processes at once: the on-board PUS process (obsw) serving TC[17,1]
with all four reports requested (TM[1,1], TM[1,3], TM[17,2], TM[1,7]); as the reference, a
bare UDP echo that answers each TC with four datagrams of the same packet; and a bare UDP echo
that answers with one (a UDP round trip). The client is the same for all: pre-packed TCs, one
socket per server for the whole run (one ground, as in operations: the process sends its TM to
every client it heard from in the last minute), raw datagrams counted. Rows: TCs per second
(a window of requests in flight) and TC-to-completion latency p50/p99 (one request at a
time), measured in short batches that alternate between the servers, the order changing from
run to run; each ratio is the median of the ratios of the batches run back to back. The goal
(issue 41): the completion report within 4 times a UDP round trip measured in the same run.

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


def serve_echo(port, replies=REPORTS):
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", port))
    print("ready", flush=True)
    while True:
        data, addr = sock.recvfrom(65536)
        for _ in range(replies):
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


def throughput(sock, target, tcs, replies=REPORTS, window=16):
    """TCs per second with ``window`` requests in flight; every report is waited for."""
    expected = len(tcs) * replies
    got = 0
    sent = 0
    t0 = time.perf_counter()
    while got < expected:
        while sent < len(tcs) and sent - got // replies < window:
            sock.sendto(tcs[sent], target)
            sent += 1
        n = _drain(sock, 2.0)
        if n == 0:
            raise RuntimeError("no answer: %d of %d reports" % (got, expected))
        got += n
    return len(tcs) / (time.perf_counter() - t0)


def latency(sock, target, tcs, replies=REPORTS):
    """Seconds from sending a TC to receiving its last (completion) report, one at a time:
    (p50, p99)."""
    out = []
    for raw in tcs:
        t0 = time.perf_counter()
        sock.sendto(raw, target)
        got = 0
        while got < replies:
            n = _drain(sock, 2.0)
            if n == 0:
                raise RuntimeError("no answer")
            got += n
        out.append(time.perf_counter() - t0)
    out.sort()
    return out[len(out) // 2], out[min(len(out) - 1, int(len(out) * 0.99))]


# server kind -> reports that answer one TC
SERVERS = {"obsw": REPORTS, "echo": REPORTS, "rtt": 1}


def measure(n_tp, n_lat, runs):
    """{kind: {"tp": [...], "p50": [...], "p99": [...]}}: one figure per run and kind, the
    kinds of a run measured back to back."""
    servers = {kind: start(kind) for kind in SERVERS}
    socks = {kind: client() for kind in SERVERS}
    out = {kind: {"tp": [], "p50": [], "p99": []} for kind in SERVERS}
    try:
        for kind, (_, target) in servers.items():  # warm up
            throughput(socks[kind], target, packets(200), SERVERS[kind])
        kinds = list(SERVERS)
        for i in range(runs):
            for kind in kinds if i % 2 == 0 else kinds[::-1]:
                target, replies = servers[kind][1], SERVERS[kind]
                out[kind]["tp"].append(throughput(socks[kind], target, packets(n_tp), replies))
                p50, p99 = latency(socks[kind], target, packets(n_lat), replies)
                out[kind]["p50"].append(p50 * 1e6)
                out[kind]["p99"].append(p99 * 1e6)
        return out
    finally:
        for sock in socks.values():
            sock.close()
        for proc, _ in servers.values():
            proc.terminate()
            proc.wait(5)


def paired(ours, theirs, higher):
    """The median of the ratios of figures measured back to back (how many times better)."""
    return statistics.median((a / b if higher else b / a) for a, b in zip(ours, theirs))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="a smaller run (under a minute)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--serve", choices=tuple(SERVERS), help=argparse.SUPPRESS)
    p.add_argument("--port", type=int, help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    if args.serve:
        try:
            if args.serve == "obsw":
                serve_obsw(args.port)
            else:
                serve_echo(args.port, SERVERS[args.serve])
        except KeyboardInterrupt:
            pass
        return 0
    n_tp, n_lat, runs = (1000, 300, 3) if args.quick else (3000, 500, 9)
    m = measure(n_tp, n_lat, runs)
    cases = (
        ("TC[17,1] with 4 reports, TCs per second", "TC/s", True, "tp", "echo"),
        ("TC to completion report, p50", "us", False, "p50", "echo"),
        ("TC to completion report, p99", "us", False, "p99", "echo"),
        ("TC to completion report, p50, against one UDP round trip", "us", False, "p50", "rtt"),
    )
    rows = []
    for case, unit, higher, key, ref in cases:
        ours, theirs = m["obsw"][key], m[ref][key]
        for impl, values in (("obsw", ours), ("reference", theirs)):
            row = {
                "case": case,
                "impl": impl,
                "value": round(statistics.median(values), 1),
                "unit": unit,
                "higher_is_better": higher,
            }
            if impl == "reference":
                row["ratio"] = round(paired(ours, theirs, higher), 3)
            rows.append(row)
    rtt = 1 / paired(m["obsw"]["p50"], m["rtt"]["p50"], False)
    note = (
        "the completion report came within %.1f UDP round trips (median of the pairs; goal 4): %s"
        % (rtt, "met" if rtt <= 4 else "MISSED")
    )
    if args.json:
        print(json.dumps({"bench": "pus_process", "rows": rows, "notes": [note]}))
        return 0
    print("%-58s %10s %10s %8s" % ("case (reference: a bare UDP echo)", "obsw", "ref.", "ratio"))
    for i in range(0, len(rows), 2):
        a, b = rows[i], rows[i + 1]
        line = (a["case"], a["value"], a["unit"][:2], b["value"], b["unit"][:2], b["ratio"])
        print("%-58s %7.1f %-2s %7.1f %-2s %7.2fx" % line)
    print("ratio: obsw relative to the reference, median of back-to-back pairs (1.00x = as fast)")
    print(note)
    return 0


if __name__ == "__main__":
    sys.exit(main())
