"""Benchmark: housekeeping packets per second that Yamcs archives from our OBC with no loss.

Yamcs (``obsw yamcs`` instance, packet links) receives TM through the packet gateway. The
source runs in a child process at a series of rates for a few seconds each:
- obsw: the on-board PUS process itself (``Onboard``), in two processes, each with N
  housekeeping structures of the sample database's panel parameters, all reported every
  cycle (10 ms), so N x 100 reports/s per process;
- reference: the same HK packet bytes, pre-encoded, sent at the same rate (Yamcs and the
  gateway alone, no OBC).
For each rate, the packets the source sent are compared with the packets Yamcs archived
(``select count(*) from tm``). The rates double from 1,000 packets/s until a packet is lost or the
ceiling of 32,000 packets/s is reached (then the page says so). Rows: the highest rate each
source reached with no packet lost.

    python tools/bench/yamcs.py [--quick] [--json]
"""

import argparse
import json
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
HERE = os.path.dirname(os.path.abspath(__file__))
# this file is named yamcs.py: keep its folder off the path so 'yamcs' is yamcs-client
sys.path = [p for p in sys.path if os.path.abspath(p or ".") != HERE]
sys.path[:0] = [os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]

PERIOD = 0.01  # the OBC's activity loop cycle in the benchmark
SKIP = 77  # exit status when Yamcs cannot run here (tools/bench/smoke.py counts a skip)
# the rates tried: doubling from START until a packet is lost, at most CEILING
START, CEILING = 1000, 32000
CEILING_NOTE = (
    "%s lost nothing at any rate tried, up to the ceiling of %d packets/s asked (it sent %d/s"
    " at most): its lossless rate is at least that, and a ratio with it says nothing more"
)


def steps(start, ceiling):
    """Rates doubling from ``start``, the last one ``ceiling``."""
    out = [start]
    while out[-1] < ceiling:
        out.append(min(out[-1] * 2, ceiling))
    return out


def bench_sdb(structures, folder):
    """The sample database with ``structures`` HK structures reported every cycle."""
    from obsw_host.sample import SDB_PATH

    with open(SDB_PATH) as f:
        doc = json.load(f)
    params = doc["housekeeping"][0]["parameters"]
    doc["housekeeping"] = [
        {"sid": 100 + i, "interval": 1, "enabled": True, "parameters": params}
        for i in range(structures)
    ]
    path = os.path.join(folder, "sdb-%d.json" % structures)
    with open(path, "w") as f:
        json.dump(doc, f)
    return path


def source_obsw(target, rate, seconds, folder, apid=10):
    """Child: the on-board PUS process reporting ``rate`` HK packets per second."""
    from obsw.pus import sdb as sdb_module
    from obsw_host.pus.onboard import Onboard
    from obsw_host.solar_panel import SOLAR_PANEL, SolarPanel

    structures = max(1, round(rate * PERIOD))
    sdb = sdb_module.load(bench_sdb(structures, folder))
    onboard = Onboard(
        sdb,
        apid=apid,
        port=0,
        period=PERIOD,
        tm_to=target,
        components=[(SOLAR_PANEL, SolarPanel())],
    )
    onboard.start()
    time.sleep(seconds)  # the load runs for a fixed time
    onboard.stop()
    return onboard.app.counters.get("tm_sent", 0)


def source_reference(target, rate, seconds, folder, apid=10):
    """Child: the same HK packet bytes (sequence counts running) at ``rate`` per second."""
    from obsw.pus.tm import PusTm
    from obsw_host.pus.onboard import tai_now

    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    data = bytes(13)  # SID 100 and three values, as large as the OBC's report
    # distinct time stamps: Yamcs keys its archive on generation time and sequence count
    t0 = int(tai_now()) << 16
    packets = [
        PusTm(apid, 3, 25, data, seq_count=i & 0x3FFF, time=divmod(t0 + 16 * i, 1 << 16)).pack()
        for i in range(int(rate * seconds) + 1)
    ]
    sent = 0
    start = time.monotonic()
    end = start + seconds
    while True:
        now = time.monotonic()
        if now >= end:
            break
        due = int((now - start) * rate)
        while sent < due:
            sock.sendto(packets[sent], target)
            sent += 1
        time.sleep(0.001)
    return sent


def child(args):
    fn = source_obsw if args.child == "obsw" else source_reference
    sent = fn(("127.0.0.1", args.target), args.rate, args.seconds, args.folder, args.apid)
    print(json.dumps({"sent": sent}), flush=True)


PROCESSES = {"obsw": 2, "reference": 1}  # one OBC process reports at most ~4,000 HK/s


def archived(client):
    rows = list(client.get_archive("obsw").execute_sql("select count(*) from tm"))
    return int(rows[0][0]) if rows else 0


def settle(client, timeout=20.0):
    """The archive count once it stops growing (Yamcs writes behind)."""
    last = archived(client)
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        time.sleep(0.5)
        now = archived(client)
        if now == last:
            return now
        last = now
    return last


def run_level(impl, rate, seconds, target, folder, client):
    before = settle(client)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path[:2]))
    n = PROCESSES[impl]
    procs = [
        subprocess.Popen(
            [
                sys.executable,
                os.path.abspath(__file__),
                "--child",
                impl,
                "--target",
                str(target),
                "--rate",
                str(rate // n),
                "--seconds",
                str(seconds),
                "--folder",
                folder,
                "--apid",
                str(10 + i),  # one APID per process: Yamcs keys packets by time and APID+count
            ],
            stdout=subprocess.PIPE,
            env=env,
            text=True,
        )
        for i in range(n)
    ]
    sent = 0
    for p in procs:
        out, _ = p.communicate()
        sent += json.loads(out.strip().splitlines()[-1])["sent"]
    got = settle(client) - before
    return sent, got


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--child", choices=("obsw", "reference"), help=argparse.SUPPRESS)
    ap.add_argument("--target", type=int, help=argparse.SUPPRESS)
    ap.add_argument("--rate", type=int, help=argparse.SUPPRESS)
    ap.add_argument("--seconds", type=float, help=argparse.SUPPRESS)
    ap.add_argument("--folder", help=argparse.SUPPRESS)
    ap.add_argument("--apid", type=int, default=10, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        return child(args)

    from obsw_host.sample import SDB_PATH
    from obsw_host.yamcs import database, server
    from obsw_host.yamcs.gateway import PacketGateway
    from obsw_host.yamcs.instance import write_instance

    problem = server.missing()
    if problem:
        print(problem, file=sys.stderr)
        return SKIP
    from yamcs.client import YamcsClient

    rates = steps(START * 4 if args.quick else START, CEILING)  # quick: 4,000/s up
    seconds = 1.0 if args.quick else 5.0
    folder = tempfile.mkdtemp(prefix="obsw-bench-yamcs-")
    probe = socket.socket()
    probe.bind(("127.0.0.1", 0))
    http_port = probe.getsockname()[1]
    probe.close()
    spacecraft = database.load(SDB_PATH)  # the sample's, its CFDP APID included
    cfdp = [spacecraft.required_apid("cfdp")]
    gateway = PacketGateway(tcp_ports={"pus": 0, "cfdp": 0}, apids={"cfdp": cfdp}, tm_port=0)
    write_instance(folder, spacecraft, "packets", gateway.ports, http_port)
    gateway.start()
    yamcs = server.Yamcs(folder, http_port)
    results, notes = {}, []
    try:
        yamcs.start(timeout=120)
        client = YamcsClient("127.0.0.1:%d" % http_port)
        while not gateway.connected("pus"):
            time.sleep(0.1)  # Yamcs' TCP link connects on its own schedule
        for impl in ("obsw", "reference"):
            best, lost = 0.0, False
            for rate in rates:
                sent, got = run_level(impl, rate, seconds, gateway.tm_address[1], folder, client)
                lossless = got >= sent
                if not args.json:
                    print(
                        "%-9s target %6d/s: sent %7d, archived %7d %s"
                        % (impl, rate, sent, got, "ok" if lossless else "LOST %d" % (sent - got)),
                        file=sys.stderr,
                    )
                if not lossless:
                    lost = True
                    break
                best = max(best, sent / seconds)
            results[impl] = best
            if not lost:
                notes.append(CEILING_NOTE % (impl, CEILING, best))
    finally:
        yamcs.stop()
        gateway.close()
        shutil.rmtree(folder, ignore_errors=True)
    rows = [
        {
            "case": "HK packets archived by Yamcs, no loss",
            "impl": impl,
            "value": round(value),
            "unit": "packets/s",
            "higher_is_better": True,
        }
        for impl, value in results.items()
    ]
    if args.json:
        print(json.dumps({"bench": "yamcs", "rows": rows, "notes": notes}))
    else:
        ref = results.get("reference") or 1
        print("%-40s %12s %12s %7s" % ("case", "obsw", "reference", "ratio"))
        print(
            "%-40s %10d/s %10d/s %6.2fx"
            % (rows[0]["case"], results["obsw"], results["reference"], results["obsw"] / ref)
        )
        for note in notes:
            print(note)
    return 0


if __name__ == "__main__":
    sys.exit(main())
