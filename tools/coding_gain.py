"""Frame error rate against Eb/N0 for uncoded, RS, convolutional and concatenated TM coding.

coding_gain.py [--frames N] [--png docs/channel-coding.png] [--json FILE] [--replot FILE]
BPSK over AWGN, soft symbols quantized to signed 8 bits for the Viterbi decoder, hard
decisions for RS alone; TM frames of 1115 octets (8920 bits, the length of CCSDS 130.1-G's
curves), RS(255,223) interleaved I=5, the pseudo-randomizer on, frame synchronization assumed
(the curves are the codes', as in 130.1-G). Eb is per bit of the TM frame: the ASM and the
check symbols are overhead. The decoders are obsw's (obsw.frames.rs, obsw.frames.viterbi).
numpy draws the noise (a development dependency, through matplotlib; not the product's).
"""

import argparse
import json
import math
import pathlib
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "micropython")]

import numpy as np  # noqa: E402
from obsw.frames import tm_coding  # noqa: E402
from obsw.frames.randomizer import randomize_tm  # noqa: E402
from obsw.frames.viterbi import Viterbi27  # noqa: E402

FRAME = 1115
DEPTH = 5
SCALE = 24  # int8 soft symbol per unit of BPSK amplitude (clipped at 127)

GRID = {
    "uncoded": [6, 7, 8, 9, 10, 11],
    "rs": [4.5, 5, 5.5, 6, 6.5],
    "conv": [3, 3.5, 4, 4.5, 5, 5.5, 6],
    "concatenated": [1.5, 1.75, 2.0, 2.25, 2.5, 2.75, 3.0],
}
CODING = {"uncoded": "none", "rs": "rs", "conv": "conv", "concatenated": "concatenated"}

# CCSDS 130.1-G-2, Figure 6-11 (word error rate of RS(255,223) I=5 with CC(7,1/2)): a word
# error rate of 1e-4 at about 2.5 dB, read off the figure (+-0.2 dB). The convolutional code
# alone is given there as a bit error rate (1e-5 at about 4.4 dB), not a frame error rate, so
# it is not drawn.
REFERENCE = {"concatenated": [(2.5, 1e-4)]}


def q(x):
    return 0.5 * math.erfc(x / math.sqrt(2))


def analytic_uncoded(ebn0_db):
    """FER of uncoded BPSK for the 8920-bit frame (and its ASM, 32 bits of overhead)."""
    eb = 10 ** (ebn0_db / 10) * 8920 / 8952
    p = q(math.sqrt(2 * eb))
    return 1 - (1 - p) ** 8920


def analytic_rs(ebn0_db):
    """FER of RS(255,223) I=5 with hard-decision BPSK: a codeword fails past 16 symbols."""
    eb = 10 ** (ebn0_db / 10) * 8920 / (8 * (1275 + 4))
    p = q(math.sqrt(2 * eb))
    ps = 1 - (1 - p) ** 8
    ok = sum(math.comb(255, i) * ps**i * (1 - ps) ** (255 - i) for i in range(17))
    return 1 - ok**DEPTH


def simulate(name, ebn0_db, frames, rng):
    coding = CODING[name]
    enc = tm_coding.TmEncoder(FRAME, coding, 16, DEPTH)
    dec = tm_coding.TmDecoder(FRAME, coding, 16, DEPTH)
    rs = dec.rs
    data = [rng.integers(0, 256, FRAME, dtype=np.uint8).tobytes() for _ in range(frames)]
    channel = b"".join(enc.encode(f) for f in data)
    bits = np.unpackbits(np.frombuffer(channel, dtype=np.uint8))
    es = 10 ** (ebn0_db / 10) * 8 * FRAME / len(bits) * frames
    sigma = math.sqrt(1 / (2 * es))
    rx = (2.0 * bits - 1.0) + rng.normal(0, sigma, len(bits))
    if enc.has_conv:
        soft = np.clip(np.round(rx * SCALE), -127, 127).astype(np.int8)
        v = Viterbi27()
        out = v.feed(soft.tobytes()) + v.flush()
        hard = np.frombuffer(out, dtype=np.uint8)
    else:
        hard = (rx > 0).astype(np.uint8)
    octets = np.packbits(hard).tobytes()
    cadu = enc.cadu_length
    errors = 0
    for i in range(frames):
        block = octets[i * cadu + 4 : (i + 1) * cadu]
        block = randomize_tm(block)
        if rs is not None:
            try:
                got = rs.decode(block)[0]
            except ValueError:
                errors += 1
                continue
        else:
            got = block
        if got != data[i]:
            errors += 1
    return errors


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=2000, help="frames per point (2000)")
    ap.add_argument("--png", default=str(ROOT / "docs" / "channel-coding.png"))
    ap.add_argument("--json", help="also write the points to this file")
    ap.add_argument("--only", choices=sorted(GRID), action="append", help="curves to run")
    ap.add_argument("--replot", help="only plot the points of an earlier --json file")
    args = ap.parse_args(argv)
    if args.replot:
        results = json.loads(pathlib.Path(args.replot).read_text())
        frames = max(n for pts in results.values() for _, _, n in pts)
        plot(results, args.png, frames)
        return 0
    rng = np.random.default_rng(2026)
    results = {}
    for name in args.only or GRID:
        pts = []
        for eb in GRID[name]:
            t0 = time.perf_counter()
            n = 0
            errs = 0
            while n < args.frames:
                k = min(200, args.frames - n)
                errs += simulate(name, eb, k, rng)
                n += k
            pts.append((eb, errs, n))
            print("%-13s Eb/N0 %5.2f dB: %6d of %6d frames lost, FER %.2e (%.0f s)" % (
                name, eb, errs, n, errs / n, time.perf_counter() - t0), flush=True)  # fmt: skip
        results[name] = pts
    if args.json:
        pathlib.Path(args.json).write_text(json.dumps(results, indent=1))
    plot(results, args.png, args.frames)
    return 0


def plot(results, png, frames):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 5))
    colors = {"uncoded": "C0", "rs": "C1", "conv": "C2", "concatenated": "C3"}
    labels = {"uncoded": "uncoded", "rs": "RS(255,223) I=5", "conv": "CC(7,1/2) soft",
              "concatenated": "RS(255,223) I=5 + CC(7,1/2)"}  # fmt: skip
    for name, pts in results.items():
        xs = [e for e, k, n in pts if k]
        ys = [k / n for e, k, n in pts if k]
        ax.semilogy(xs, ys, "o-", color=colors[name], label="obsw, " + labels[name])
        for e, k, n in pts:
            if not k:  # no frame lost: an upper bound at one frame
                ax.semilogy([e], [1 / n], "v", color=colors[name])
    grid = [x / 4 for x in range(0, 50)]
    ax.semilogy(grid, [analytic_uncoded(x) for x in grid], ":", color="C0",
                label="uncoded, theory")  # fmt: skip
    ax.semilogy(grid, [analytic_rs(x) for x in grid], ":", color="C1",
                label="RS I=5 hard decisions, theory")  # fmt: skip
    for name, pts in REFERENCE.items():
        ax.semilogy([p[0] for p in pts], [p[1] for p in pts], "s", mfc="none", ms=9,
                    color=colors[name], label="130.1-G-2 figures, " + labels[name])  # fmt: skip
    ax.set_xlim(0, 12)
    ax.set_ylim(1e-5, 1.5)
    ax.set_xlabel("Eb/N0 (dB), Eb per bit of the 8920-bit TM frame")
    ax.set_ylabel("frame error rate")
    ax.set_title("CCSDS 131.0-B coding gain, BPSK on AWGN, %d frames per point" % frames)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    print("wrote", png)


if __name__ == "__main__":
    sys.exit(main())
