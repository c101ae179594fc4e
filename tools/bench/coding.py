"""Benchmark CCSDS 131.0-B channel coding: Reed-Solomon, convolutional encoder, Viterbi (ours vs
libfec).

coding.py [--quick] [--json]
The peer is Debian's libfec (Phil Karn's C library, package libfec0) through ctypes, measured in
the same run on the same input, runs paired back to back; the ratio is the median of the pairs'
ratios. libfec has no convolutional encoder: that row has no peer. The goal is a 2 Mbit/s S-band
downlink: the ground's decoders keep up on one core, the OBC's encoders take under 5 % of one.
"""

import argparse
import array
import json
import pathlib
import random
import statistics
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path[:0] = [str(ROOT / "micropython"), str(ROOT / "tests" / "interop")]

from measure import rate  # noqa: E402
from obsw.frames import conv, rs, viterbi  # noqa: E402

LINK = 2_000_000  # channel bit/s of the S-band goal
GROUND_SHARE = 1.0  # one core
OBC_SHARE = 0.05


def cases(quick):
    rnd = random.Random(1)
    data = bytes(rnd.randrange(256) for _ in range(223))
    code = rs.ReedSolomon(16)
    block = code.encode(data)
    bad = bytearray(block)
    for p in rnd.sample(range(255), 16):
        bad[p] ^= rnd.randrange(1, 256)
    bad = bytes(bad)
    cadu = bytes(rnd.randrange(256) for _ in range(1279))  # ASM + RS(255,223) x5 codeblock
    coded = conv.ConvEncoder().encode(cadu)
    clean = viterbi.soft_from_bits(coded, 60)
    soft = array.array("b", [max(-127, min(127, int(s + rnd.gauss(0, 40)))) for s in clean])
    nbits = len(cadu) * 8

    def vit(fast):
        def run():
            v = viterbi.Viterbi27(fast=fast)
            v.feed(soft)
            v.flush()

        return run

    pure_soft = soft[: 2 * 8 * 64]  # the Python loop on a slice (64 octets), scaled below

    def vit_pure():
        v = viterbi.Viterbi27(fast=False)
        v.feed(pure_soft)
        v.flush()

    # (case, unit, function, channel bits per call, side)
    rows = [
        ("RS(255,223) encode, one codeword", "codeword/s", lambda: code.encode(data),
         255 * 8, "obc"),
        ("RS(255,223) decode, clean codeword", "codeword/s", lambda: code.decode(block),
         255 * 8, "ground"),
        ("RS(255,223) decode, 16 symbol errors", "codeword/s", lambda: code.decode(bad),
         255 * 8, "ground"),
        ("conv K=7 r=1/2 encode, 1279-octet CADU", "CADU/s",
         lambda: conv.ConvEncoder().encode(cadu), 2 * nbits, "obc"),
        ("Viterbi K=7 soft decode, 1279-octet CADU", "CADU/s", vit(None), 2 * nbits, "ground"),
        ("Viterbi K=7 soft decode, Python loop", "CADU/s", vit_pure, 2 * nbits, "ground"),
    ]  # fmt: skip
    peers = {}
    import libfec_peer

    fec = libfec_peer.load()
    if fec is not None:
        tail = coded + conv.ConvEncoder(cadu[-1] & 0x3F).encode(b"\x00")
        usoft = bytes(
            max(0, min(255, 128 + s))
            for s in list(soft) + viterbi.soft_from_bits(tail[len(coded) :], 60)[:12]
        )
        peers[rows[0][0]] = lambda: fec.rs_encode(data)
        peers[rows[1][0]] = lambda: fec.rs_decode(block)
        peers[rows[2][0]] = lambda: fec.rs_decode(bad)
        peers[rows[4][0]] = lambda: fec.viterbi27(usoft, nbits + 6)
        peers[rows[5][0]] = peers[rows[4][0]]
    return rows, peers, libfec_peer.reason


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="short runs (smoke check)")
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    args = ap.parse_args(argv)
    seconds, repeats = (0.1, 3) if args.quick else (0.5, 7)
    rows, peers, why = cases(args.quick)
    out = []
    goals = []
    for name, unit, fn, bits, side in rows:
        fn()
        ours_runs, ratios, theirs_runs = [], [], []
        peer = peers.get(name)
        if peer is not None:
            peer()
        for _ in range(repeats):
            o = rate(fn, seconds, 1)
            ours_runs.append(o)
            if peer is not None:
                t = rate(peer, seconds, 1)
                theirs_runs.append(t)
                ratios.append(o / t)
        if name.endswith("Python loop"):  # measured on 64 octets: per CADU
            ours_runs = [r * 64 / 1279 for r in ours_runs]
            ratios = [r * 64 / 1279 for r in ratios]
        ours = statistics.median(ours_runs)
        out.append((name, "obsw", ours, unit, None))
        if peer is not None:
            out.append((name, "libfec", statistics.median(theirs_runs), unit, None))
            out.append((name + ": ratio obsw/libfec", "obsw", statistics.median(ratios), "x",
                        None))  # fmt: skip
        share = LINK / (ours * bits)  # of one core at the goal's line rate
        limit = OBC_SHARE if side == "obc" else GROUND_SHARE
        goals.append((name, side, share, limit))
        out.append((name + ": share of a core at 2 Mbit/s", "obsw", share * 100, "%", False))
    if args.json:
        print(json.dumps({"bench": "coding", "rows": [
            {"case": c, "impl": i, "value": v, "unit": u,
             "higher_is_better": True if h is None else h}
            for c, i, v, u, h in out]}))  # fmt: skip
        return 0
    print("%-66s %-7s %12s %-11s" % ("case", "impl", "median", "unit"))
    for c, i, v, u, _ in out:
        print("%-66s %-7s %12.2f %-11s" % (c, i, v, u))
    if not peers:
        print("libfec not measured: %s" % why)
    print()
    print("Goal: a 2 Mbit/s S-band link (channel bits; r=1/2 halves the CADU rate). Ground")
    print("decoders keep up on one core, OBC encoders under 5 % of a core:")
    for name, side, share, limit in goals:
        verdict = "met" if share <= limit else "%.1fx short" % (share / limit)
        print("  %-45s %-6s %7.1f %% of a core (goal %3.0f %%): %s" % (
            name, side, share * 100, limit * 100, verdict))  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
