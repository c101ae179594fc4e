"""Benchmark: TC-to-completion latency through the whole chain (``obsw_sim.chain``).

One run starts the chain (ground station, pseudo-terminal UARTs, the OBC as three processes
under its platform manager, the CAN hub and both MicroPython reconfiguration controllers) and
measures, one request at a time:
- a ping (TC[17,1]) through CLTUs, the frame processor and TM frames, to its completion report;
- a CPDU switch: TC[18,3] activating a PLUTO procedure that calls ``CpduN.set_state_bits``
  over SpaceCAN, to the procedure's ``obcp.finished`` event back through the TM frames;
- the reference: the same ping over UDP straight to the PUS process.
Rows: p50 and p99 in milliseconds. The chain's ping is also cut into its hops, from the ground
station's two UART ends (timed where the station writes the TC's CLTU and reads the TM frames,
in this process): the ground's uplink (the PUS user to the station over UDP, TC frame, SDLS,
CLTU, onto the UART), the OBC (from the CLTU on the UART to the first TM frame back: frame
processor, PUS process, TM frames) and the ground's downlink (from the first TM frame to the
completion report at the PUS user); each hop's p50 is given next to the direct ping's.

    python tools/bench/chain.py [--quick] [--json]
"""

import argparse
import json
import os
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path[:0] = [os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]

from measure import row  # noqa: E402
from obsw_sim.chain import SWITCH, Chain  # noqa: E402


def percentiles(samples):
    s = sorted(samples)
    return s[len(s) // 2], s[min(len(s) - 1, int(len(s) * 0.99))]


def pings(ground, n, marks=None):
    """Seconds of ``n`` pings; with ``marks`` (a list the links append (kind, time) to), also
    [(uplink, obc, downlink)] seconds of each."""
    out, hops = [], []
    for _ in range(n):
        if marks is not None:
            del marks[:]
        t0 = time.perf_counter()
        tx = ground.ping(timeout=5.0)
        t1 = time.perf_counter()
        out.append(t1 - t0)
        if not tx.ok:
            raise RuntimeError("ping failed: %s" % tx.verification())
        if marks is not None:
            up = [t for kind, t in marks if kind == "w"]
            down = [t for kind, t in marks if kind == "r" and t > up[0]] if up else []
            if up and down:
                hops.append((up[0] - t0, down[0] - up[0], t1 - down[0]))
    return (out, hops) if marks is not None else out


def mark_links(links, marks):
    """Time-stamp each write (the TC's CLTU) and each read that brought data (TM frames) on
    the station's UART ends."""
    for link in links:
        write, read = link.write, link.read

        def w(data, write=write):
            marks.append(("w", time.perf_counter()))
            return write(data)

        def r(read=read):
            data = read()
            if data:
                marks.append(("r", time.perf_counter()))
            return data

        link.write, link.read = w, r


def switches(chain, n):
    """Activate the loaded switch procedures in turn; time to their obcp.finished event."""
    states = (0x005, 0x003)
    for i, state in enumerate(states):
        text = SWITCH % (chain.cpdu, state | chain.obc_bit)
        tx = chain.obcp.load("sw%d" % i, text, timeout=10.0)
        if not tx.ok:
            raise RuntimeError("load refused: %s" % tx.verification())
    out = []
    for k in range(n):
        i = k % len(states)
        since = len(chain.ground.received)
        t0 = time.perf_counter()
        tx = chain.obcp.activate("sw%d" % i, timeout=10.0)
        end = chain.wait_event(("obcp.finished", "obcp.failed"), since, 10.0)
        out.append(time.perf_counter() - t0)
        if not tx.ok or end != "obcp.finished":
            raise RuntimeError("switch %d: %s, %s" % (k, tx.verification(), end))
    return out


def run(n_ping, n_switch):
    from obsw_host.pus.ground import Ground

    rows = []
    with tempfile.TemporaryDirectory(prefix="obsw-bench-chain-") as work:
        with Chain(work) as chain:
            chain.wait_up(60.0)
            pings(chain.ground, 20)  # warm up
            marks = []
            mark_links(chain.links, marks)
            frames, hops = pings(chain.ground, n_ping, marks)
            switch = switches(chain, n_switch)
            direct_ground = Ground(chain.sdb, target=("127.0.0.1", chain.pus_port))
            try:
                pings(direct_ground, 20)
                direct = pings(direct_ground, n_ping)
            finally:
                direct_ground.close()
    for case, samples in zip(HOPS, zip(*hops)):
        rows.append(_row("ping, hop: %s, p50" % case, "obsw", percentiles(samples)[0]))
        rows.append(_row("ping, hop: %s, p50" % case, "reference", percentiles(direct)[0]))
    for case, impl, samples in (
        ("ping through the chain (CLTU, frames, TM frames)", "obsw", frames),
        ("CPDU switch through the chain (18 -> PLUTO -> SpaceCAN)", "obsw", switch),
        ("ping over UDP straight to the PUS process", "reference", direct),
    ):
        p50, p99 = percentiles(samples)
        for name, v in (("p50", p50), ("p99", p99)):
            rows.append(
                {
                    "case": "%s, %s" % (case, name),
                    "impl": impl,
                    "value": round(v * 1000, 3),
                    "unit": "ms",
                    "higher_is_better": False,
                }
            )
    return rows


HOPS = (
    "ground uplink (PUS user, station, TC frame, SDLS, CLTU onto the UART)",
    "OBC (CLTU on the UART to the first TM frame: frame processor, PUS process)",
    "ground downlink (first TM frame to the completion report at the PUS user)",
)


def _row(case, impl, seconds):
    return row(case, impl, round(seconds * 1000, 3), "ms", False)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="a smaller run (under a minute)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    args = p.parse_args(argv)
    n_ping, n_switch = (100, 20) if args.quick else (500, 100)
    rows = run(n_ping, n_switch)
    if args.json:
        print(json.dumps({"bench": "chain", "rows": rows}))
        return 0
    print("%-72s %-9s %10s" % ("case", "impl", "ms"))
    for r in rows:
        print("%-72s %-9s %10.2f" % (r["case"], r["impl"], r["value"]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
