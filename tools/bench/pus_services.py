"""PUS service requests served per second: obsw's providers against puslib's, same TC bytes.

Each request is a whole TC packet in, decoded, executed and answered with its reports packed:
TC[3,28] one-shot diagnostic report of 8 float32 parameters (TM[3,26]) and TC[3,34] periodic
generation properties of 4 diagnostic structures (TM[3,36]), requests both libraries serve.
The TC bytes are built once by obsw's service user and are the same for both providers; they
ask for every verification report, which obsw sends (acceptance, start, completion) and
puslib partly (acceptance, completion): obsw packs one TM more per request.

Usage: python tools/bench/pus_services.py [--quick] [--json]
"""

import argparse
import json
import os
import statistics
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path[:0] = [os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]

from measure import batch_size  # noqa: E402
from obsw.il.clock import SimClock  # noqa: E402
from obsw.pus.app import ApplicationProcess  # noqa: E402
from obsw.pus.fields import field  # noqa: E402
from obsw.pus.services.s03_housekeeping import Housekeeping, HousekeepingUser  # noqa: E402
from obsw.pus.user import UserProcess  # noqa: E402

APID = 10
PIDS = list(range(1, 9))
FLOAT32 = field(5, 1)
STRUCTURES = [{"sid": s, "interval": s, "parameters": PIDS, "enabled": True} for s in (1, 2, 3, 4)]


class Pool:
    """The least a parameter pool gives the housekeeping provider."""

    def __init__(self):
        self.values = {pid: pid * 1.5 for pid in PIDS}

    def __contains__(self, pid):
        return pid in self.values

    def get(self, pid):
        return self.values[pid]

    def type_of(self, pid):
        return FLOAT32


def requests():
    """(case, TC bytes) built by obsw's service user."""
    sent = []
    user_proc = UserProcess(sent.append, SimClock(0.0), source_id=7)
    user = user_proc.register(HousekeepingUser(lambda pid: FLOAT32))
    out = []
    user.one_shot(APID, [1], "diag")
    out.append(("TC[3,28] -> TM[3,26] 8 x float32", sent[-1]))
    user.report_properties(APID, [1, 2, 3, 4], "diag")
    out.append(("TC[3,34] -> TM[3,36] 4 structures", sent[-1]))
    return out


def obsw_server(raw):
    sink = []
    app = ApplicationProcess(APID, sink.append, SimClock(0.0))
    app.register(Housekeeping(Pool(), diagnostic=STRUCTURES))

    def run(n):
        for _ in range(n):
            app.receive(raw)
        if len(sink) < n:
            raise AssertionError("no reports")
        sink.clear()

    return run


def puslib_server(raw):
    from puslib.ident import PusIdent
    from puslib.packet import PusTcPacket
    from puslib.parameter import Real32Parameter
    from puslib.services import RequestVerification
    from puslib.services.pus_003_housekeeping import Housekeeping as PuslibHousekeeping
    from puslib.streams.buffer import QueuedOutput

    ident = PusIdent(APID)
    out = QueuedOutput()
    params = {pid: Real32Parameter(pid * 1.5) for pid in PIDS}
    hk = PuslibHousekeeping(ident, RequestVerification(ident, out), out, params)
    for s in STRUCTURES:
        hk.add(s["sid"], s["interval"], {p: params[p] for p in PIDS}, diagnostic=True)

    def run(n):
        for _ in range(n):
            hk.enqueue(PusTcPacket.deserialize(raw))
            hk.process()
            while not out.empty():
                out.get().serialize()  # packed, as obsw packs its TM

    return run


IMPLS = (("obsw", obsw_server), ("puslib", puslib_server))


def measure(runs, seconds, repeats):
    """Median requests per second of each run, the timed batches interleaved."""
    sizes = [batch_size(run, seconds, most=1 << 20) for run in runs]
    rates = [[] for _ in runs]
    for _ in range(repeats):
        for run, n, out in zip(runs, sizes, rates):
            t0 = time.perf_counter()
            run(n)
            out.append(n / (time.perf_counter() - t0))
    return [statistics.median(r) for r in rates]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="short runs (a few seconds in all)")
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    args = ap.parse_args(argv)
    seconds, repeats = (0.1, 3) if args.quick else (0.5, 7)
    rows = []
    for case, raw in requests():
        impls, runs = [], []
        for impl, make in IMPLS:
            try:
                runs.append(make(raw))
            except ImportError:
                continue  # peer not installed
            impls.append(impl)
        for impl, value in zip(impls, measure(runs, seconds, repeats)):
            rows.append({"case": case, "impl": impl, "value": round(value, 1),
                         "unit": "requests/s", "higher_is_better": True})  # fmt: skip
    if args.json:
        print(json.dumps({"bench": "pus_services", "rows": rows}))
        return 0
    print("%-36s %-8s %12s %12s" % ("case", "impl", "requests/s", "obsw ratio"))
    for case, _ in requests():
        mine = [r for r in rows if r["case"] == case]
        ours = next(r["value"] for r in mine if r["impl"] == "obsw")
        for r in mine:
            ratio = "" if r["impl"] == "obsw" else "%.2fx" % (ours / r["value"])
            print("%-36s %-8s %12.0f %12s" % (case, r["impl"], r["value"], ratio))
    return 0


if __name__ == "__main__":
    sys.exit(main())
