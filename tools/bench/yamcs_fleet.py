"""Benchmark: N spacecraft on one Yamcs server against one spacecraft on one Yamcs server.

The fleet (obsw): N missions written from the sample by ``obsw mission new --count N``, each
its own spacecraft id and ports, on one Yamcs with an instance per mission
(``obsw yamcs config --mission ... --mission ...``). The reference: one such mission alone on
its own Yamcs. Each spacecraft's link runs in a child process of its own, as each OBC would:
the packet gateway of ``obsw yamcs run --obc`` (Yamcs' TCP packet links on one side) fed with
housekeeping packets, pre-encoded with the mission's layout and distinct time stamps, at a set
rate. Per spacecraft:
- the highest housekeeping rate every spacecraft reached at once with no packet lost (sent
  against what its instance archived, ``select count(*) from tm``), of 250, 500, 1000, 2000,
  4000, 8000 and 16000 packets per second for 5 s each (16000: as high as it goes);
- Yamcs' CPU (user + system time over wall time, % of one core) with every spacecraft sending
  100 packets per second, divided by N;
- Yamcs' resident memory after that, divided by N;
- Yamcs' start until every instance runs, divided by N.

    python tools/bench/yamcs_fleet.py [--quick] [--json] [--count N]
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
# tools/bench has a yamcs.py: keep its folder off the path so 'yamcs' is yamcs-client
sys.path = [p for p in sys.path if os.path.abspath(p or ".") != HERE]
sys.path[:0] = [os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]

SAMPLE = os.path.join(ROOT, "examples", "sample")
STEADY = 100  # packets per second per spacecraft for the CPU and memory figures
SKIP = 77  # exit status when Yamcs cannot run here (tools/bench/smoke.py counts a skip)
RATES = [250, 500, 1000, 2000, 4000, 8000, 16000]  # tried in turn until a packet is lost
CEILING_NOTE = (
    "%s lost nothing up to the ceiling of %d packets/s per spacecraft: its lossless rate is at"
    " least that, and a ratio between figures at the ceiling says nothing"
)


# ------------------------------------------------------------------------------ child


def child(args):
    """One spacecraft's link: the packet gateway on the mission's Yamcs ports, and on each
    ``RATE SECONDS`` line of standard input that many HK packets per second sent through it;
    answers each with the count sent."""
    from obsw.pus.tm import PusTm
    from obsw_host.mission.ids import MissionIds
    from obsw_host.pus.onboard import tai_now
    from obsw_host.yamcs.gateway import PacketGateway

    ids = MissionIds.locate(args.child)
    ports = ids.ports.yamcs()
    cfdp = ids.apid("cfdp")
    gateway = PacketGateway(
        tcp_ports={"pus": ports["pus"], "cfdp": ports["cfdp"]}, apids={"cfdp": [cfdp]}, tm_port=0
    )
    gateway.start()
    while not gateway.connected("pus"):
        time.sleep(0.05)  # Yamcs' TCP link connects on its own schedule
    print("ready", flush=True)
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    target = gateway.tm_address
    apid = ids.pus_apid
    data = bytes(13)  # a SID and three values, as large as the sample's report
    last = 0
    for line in sys.stdin:
        rate, seconds = float(line.split()[0]), float(line.split()[1])
        # distinct time stamps, never one of an earlier run's (a rate's packets may span more
        # time than it took to send them): Yamcs keys its archive on time and sequence count
        t0 = max(int(tai_now()) << 16, last)
        last = t0 + 16 * (int(rate * seconds) + 2)
        packets = [
            PusTm(
                apid, 3, 25, data, seq_count=i & 0x3FFF, time=divmod(t0 + 16 * i, 1 << 16)
            ).pack()
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
        print(json.dumps({"sent": sent}), flush=True)
    gateway.close()


# ------------------------------------------------------------------------------ parent


def proc_cpu(pid):
    """User + system CPU seconds of process ``pid`` (Linux /proc)."""
    with open("/proc/%d/stat" % pid) as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def proc_rss_mb(pid):
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return 0.0


class Setup:
    """N missions, one Yamcs with an instance each, and a link child per spacecraft."""

    def __init__(self, count, folder):
        from obsw_host.mission import new
        from obsw_host.mission.ids import MissionIds
        from obsw_host.yamcs import database, fleet, server
        from obsw_host.yamcs.instance import Member, write_fleet

        os.environ.pop("OBSW_PORT_BASE", None)  # each mission its own base
        base = new.free_fleet_base(count)
        folders = new.fleet(SAMPLE, "sc", os.path.join(folder, "missions"), count, port_base=base)
        self.missions = [MissionIds.locate(f) for f in folders]
        self.names = [ids.name for ids in self.missions]
        http = self.missions[0].ports.yamcs_http
        fleet.check(self.missions, http)
        members = [
            Member(ids.name, database.from_ids(ids), "packets", None, ids) for ids in self.missions
        ]
        yfolder = os.path.join(folder, "yamcs")
        write_fleet(yfolder, members, http)
        self.yamcs = server.Yamcs(yfolder, http, instance=self.names[0])
        self.children = []
        try:
            self._start(folders, http)
        except BaseException:
            self.close()
            raise

    def _start(self, folders, http):
        from yamcs.client import YamcsClient

        t0 = time.monotonic()
        self.yamcs.start(timeout=300)
        for name in self.names[1:]:
            self.yamcs.instance = name
            while self.yamcs.state() != "RUNNING":
                time.sleep(0.2)  # polling Yamcs' HTTP API
        self.startup = time.monotonic() - t0
        self.client = YamcsClient("127.0.0.1:%d" % http)
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path[:2]))
        for f in folders:
            self.children.append(
                subprocess.Popen(
                    [sys.executable, os.path.abspath(__file__), "--child", f],
                    stdin=subprocess.PIPE,
                    stdout=subprocess.PIPE,
                    env=env,
                    text=True,
                )
            )
        for c in self.children:
            assert c.stdout.readline().strip() == "ready"

    def archived(self, name):
        rows = list(self.client.get_archive(name).execute_sql("select count(*) from tm"))
        return int(rows[0][0]) if rows else 0

    def settle(self, timeout=30.0):
        """Each instance's archive count once none grows any more (Yamcs writes behind)."""
        last = [self.archived(n) for n in self.names]
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            time.sleep(0.5)
            now = [self.archived(n) for n in self.names]
            if now == last:
                return now
            last = now
        return last

    def send(self, rate, seconds):
        """Every spacecraft sends ``rate`` packets/s for ``seconds`` at once; returns the
        packets each sent."""
        for c in self.children:
            c.stdin.write("%g %g\n" % (rate, seconds))
            c.stdin.flush()
        return [json.loads(c.stdout.readline())["sent"] for c in self.children]

    def lossless_rate(self, rates, seconds, label, quiet):
        """The highest of ``rates`` every spacecraft reached at once with no loss, and whether
        the last one was reached without loss (the ceiling: the figure is a lower bound)."""
        best = 0.0
        before = self.settle()
        for rate in rates:
            sent = self.send(rate, seconds)
            after = self.settle()
            got = [b - a for a, b in zip(before, after)]
            before = after
            lost = sum(max(0, s - g) for s, g in zip(sent, got))
            if not quiet:
                print("%-10s %6d/s each: sent %8d, archived %8d %s"
                      % (label, rate, sum(sent), sum(got), "ok" if not lost else "LOST %d" % lost),
                      file=sys.stderr)  # fmt: skip
            if lost:
                return best, False
            best = min(sent) / seconds
        return best, True

    def steady(self, seconds):
        """Yamcs' CPU (% of a core) and RSS (MB) with every spacecraft at STEADY packets/s."""
        pid = self.yamcs.process.pid
        cpu0, t0 = proc_cpu(pid), time.monotonic()
        self.send(STEADY, seconds)
        cpu = (proc_cpu(pid) - cpu0) / (time.monotonic() - t0) * 100.0
        return cpu, proc_rss_mb(pid)

    def close(self):
        for c in self.children:
            try:
                c.stdin.close()
                c.wait(10)
            except (OSError, subprocess.TimeoutExpired):
                c.kill()
        self.yamcs.stop()


def measure(count, rates, seconds, quiet):
    folder = tempfile.mkdtemp(prefix="obsw-bench-fleet-")
    setup = None
    try:
        setup = Setup(count, folder)
        label = "%d x 1" % count
        rate, ceiling = setup.lossless_rate(rates, seconds, label, quiet)
        cpu, rss = setup.steady(max(seconds, 5.0))
        out = {
            "rate": rate,
            "cpu": cpu / count,
            "rss": rss / count,
            "startup": setup.startup / count,
            "ceiling": ceiling,
        }
        if not quiet:
            print("%-10s %s" % (label, json.dumps({k: round(v, 2) for k, v in out.items()
                                                   if k != "ceiling"})),
                  file=sys.stderr)  # fmt: skip
        return out
    finally:
        if setup is not None:
            setup.close()
        shutil.rmtree(folder, ignore_errors=True)


CASES = [
    ("rate", "HK packets archived per spacecraft, every one at once, no loss", "packets/s", True),
    ("cpu", "Yamcs CPU per spacecraft at %d HK packets/s each" % STEADY, "% of a core", False),
    ("rss", "Yamcs resident memory per spacecraft", "MB", False),
    ("startup", "Yamcs start until every instance runs, per spacecraft", "s", False),
]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--count", type=int, help="spacecraft on the shared Yamcs (default 10)")
    ap.add_argument("--child", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        return child(args)
    from obsw_host.yamcs import server

    problem = server.missing()
    if problem:
        print(problem, file=sys.stderr)
        return SKIP
    count = args.count or (2 if args.quick else 10)
    # up until a packet is lost, at most 16,000/s (the quick run in larger steps)
    rates = [2000, 8000, 16000] if args.quick else RATES
    seconds = 1.0 if args.quick else 5.0
    results = {
        "obsw": measure(count, rates, seconds, False),  # progress on stderr, the result on stdout
        "reference": measure(1, rates, seconds, False),
    }
    notes = [
        CEILING_NOTE % (impl, rates[-1])
        for impl in ("obsw", "reference")
        if results[impl]["ceiling"]
    ]
    rows = []
    for key, case, unit, higher in CASES:
        for impl in ("obsw", "reference"):
            value = results[impl][key]
            rows.append(
                {
                    "case": "%s (%d on one Yamcs against 1)" % (case, count),
                    "impl": impl,
                    "value": round(value) if key == "rate" else round(value, 3),
                    "unit": unit,
                    "higher_is_better": higher,
                }
            )
    if args.json:
        print(json.dumps({"bench": "yamcs_fleet", "count": count, "rows": rows, "notes": notes}))
        return 0
    print("%-66s %12s %12s %7s" % ("case", "%d on one" % count, "1 on one", "ratio"))
    for key, case, unit, higher in CASES:
        ours, ref = results["obsw"][key], results["reference"][key]
        q = (ours / ref if higher else ref / ours) if ours and ref else float("nan")
        print("%-66s %12.4g %12.4g %6.2fx  %s" % (case, ours, ref, q, unit))
    for note in notes:
        print(note)
    return 0


if __name__ == "__main__":
    sys.exit(main())
