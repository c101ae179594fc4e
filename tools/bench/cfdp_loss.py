"""CFDP class 2 over UDP with 10 % of the uplink's PDUs lost: octets sent per octet of file.

One file (50 MiB, 5 MiB with --quick, random bytes on disk) goes class 2 (acknowledged,
closure requested) from `CfdpClient` (the library behind `obsw cfdp put`) in this process to
`obsw cfdp serve` in a child process, each on its own UDP socket on 127.0.0.1, files on disk on
both sides, 1,024-octet segments, 1 s ACK and NAK timers. The sender drops 10 % of the PDUs it
sends, at random (``--loss``): file data, metadata, EOF alike. The figure is the file data
octets the sender put on the link (first sends and retransmissions, lost ones included) over
the file's size; the reference is what a perfect retransmission scheme needs at that loss,
1 / (1 - loss). The goal is at most 1.5. The received file is compared with the original.
The time and the rate are shown for information (they depend on the machine's load).

Usage: python tools/bench/cfdp_loss.py [--quick] [--json] [--runs N] [--loss P]
"""

import argparse
import json
import os
import random
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

from measure import child_env, free_port  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path[:0] = [os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]

MIB = 1 << 20
SEGMENT = 1024
GOAL = 1.5


def transfer(work, run, data, loss):
    """One upload; (octets sent / file size, seconds, delivered and equal)."""
    from obsw_host.cfdp.client import CfdpClient
    from obsw_host.sample import MISSION_DIR, load_sdb

    rx_root = os.path.join(work, "rx%d" % run)
    tx_root = os.path.join(work, "tx%d" % run)
    os.makedirs(rx_root)
    os.makedirs(tx_root)
    rx_port, tx_port = free_port(), free_port()
    proc = subprocess.Popen(
        [sys.executable, "-m", "obsw_host.cfdp", "serve", "--id", "2", "--root", rx_root,
         "--port", str(rx_port), "--peer", "1=127.0.0.1:%d" % tx_port,
         "--mission", MISSION_DIR],
        stdout=subprocess.PIPE, text=True,
        env=dict(child_env(), OBSW_STATE=os.path.join(work, "state-rx%d" % run)),
    )  # fmt: skip
    try:
        line = proc.stdout.readline()
        if "cfdp entity 2" not in line:
            raise SystemExit("obsw cfdp serve did not start: %r" % line)
        with open(os.path.join(tx_root, "f.bin"), "wb") as f:
            f.write(data)
        client = CfdpClient(1, {2: ("127.0.0.1", rx_port)}, tx_root, apid=load_sdb().apid("cfdp"),
                            cls=2, segment=SEGMENT, port=tx_port, loss=loss, timeout=900,
                            state=os.path.join(work, "state-tx"))  # fmt: skip
        client.udp.rng.seed(run + 1)
        try:
            t0 = time.perf_counter()
            result = client.put("f.bin", "f.bin")
            dt = time.perf_counter() - t0
            st = client.entity.stats
            sent = st["file_bytes_sent"] + st["retransmitted_bytes"]
        finally:
            client.close()
        with open(os.path.join(rx_root, "f.bin"), "rb") as f:
            same = result.delivered and f.read() == data
        return sent / len(data), dt, same
    finally:
        if proc.poll() is None:
            proc.terminate()
            try:
                proc.wait(10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait(10)
        proc.stdout.close()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="5 MiB, one run")
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    ap.add_argument("--runs", type=int, help="runs (default 3, quick 1)")
    ap.add_argument("--loss", type=float, default=0.1, help="fraction of PDUs lost (0.1)")
    args = ap.parse_args(argv)
    mib = 5 if args.quick else 50
    runs = args.runs or (1 if args.quick else 3)
    data = random.Random(mib).randbytes(mib * MIB)
    work = tempfile.mkdtemp(prefix="obsw-cfdp-loss-")
    ratios, rates = [], []
    try:
        for r in range(runs):
            ratio, dt, ok = transfer(work, r, data, args.loss)
            if not ok:
                raise SystemExit("run %d: the file was not delivered whole" % (r + 1))
            ratios.append(ratio)
            rates.append(len(data) / dt / 1e6)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    case = "class 2 %d MiB over UDP, %g %% loss" % (mib, args.loss * 100)
    ours = statistics.median(ratios)
    ideal = 1 / (1 - args.loss)
    if args.json:
        rows = [
            {"case": case, "impl": "obsw", "value": round(ours, 3), "unit": "sent/size",
             "higher_is_better": False},
            {"case": case, "impl": "reference", "value": round(ideal, 3), "unit": "sent/size",
             "higher_is_better": False},
            {"case": case, "impl": "obsw", "value": round(statistics.median(rates), 2),
             "unit": "MB/s", "higher_is_better": True},
        ]  # fmt: skip
        print(json.dumps({"bench": "cfdp_loss", "rows": rows}))
        return 0 if ours <= GOAL else 1
    print("%-36s %10s %10s %8s" % ("case", "obsw", "reference", "ratio"))
    print("%-36s %10.3f %10.3f %7.2fx  octets sent / file size (goal <= %.1f)" % (
        case, ours, ideal, ours / ideal, GOAL))  # fmt: skip
    print("%-36s %10.2f %10s %8s  MB/s (median of %d)" % (
        "", statistics.median(rates), "-", "", runs))  # fmt: skip
    return 0 if ours <= GOAL else 1


if __name__ == "__main__":
    sys.exit(main())
