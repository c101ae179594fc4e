"""gr-satellites (GNU Radio 3.10, Debian) deframes the coded TM stream we produce with its own
CCSDS deframers and gives back our frames byte for byte."""

import os
import random
import struct
import subprocess

import pytest
from obsw.frames.tm import TmFrame
from obsw.frames.tm_coding import TmEncoder
from obsw.frames.viterbi import soft_from_bits

SYSTEM_PYTHON = "/usr/bin/python3"  # Debian's, where GNU Radio's Python modules live
HELPER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "grsat_deframe.py")


def _gnuradio_reason():
    if not os.path.exists(SYSTEM_PYTHON):
        return "no %s for Debian's GNU Radio" % SYSTEM_PYTHON
    probe = subprocess.run(
        [SYSTEM_PYTHON, "-c", "import gnuradio.gr, satellites, pmt"],
        capture_output=True,
        text=True,
    )
    if probe.returncode:
        lines = probe.stderr.strip().splitlines() or ["?"]
        return "GNU Radio / gr-satellites cannot import (apt-get install gnuradio "
        "gr-satellites): %s" % lines[-1]
    return None


REASON = _gnuradio_reason()
pytestmark = pytest.mark.skipif(REASON is not None, reason=REASON or "")


def _frames(n, length, seed):
    rnd = random.Random(seed)
    return [
        TmFrame(0x2A, 1, bytes(rnd.randrange(256) for _ in range(length - 8)), mc_count=i).pack()
        for i in range(n)
    ]


def _deframe(tmp_path, coding, frames, depth, noise, seed):
    enc = TmEncoder(len(frames[0]), coding, 16, depth)
    stream = b"".join(enc.encode(f) for f in frames)
    # idle frames after ours, so each repetition of the symbols starts clean
    stream += b"".join(enc.encode(bytes(len(frames[0]))) for _ in range(2))
    rnd = random.Random(seed)
    soft = [s + rnd.gauss(0, noise) for s in soft_from_bits(stream, 1)]
    path = tmp_path / "symbols.f32"
    path.write_bytes(struct.pack("<%df" % len(soft), *soft))
    kind = "rs" if coding == "rs" else "concatenated"
    out = subprocess.run(
        [SYSTEM_PYTHON, HELPER, str(path), kind, str(len(frames[0])), str(depth),
         str(len(frames) + 2)],
        capture_output=True,
        text=True,
        timeout=300,
    )  # fmt: skip
    assert out.returncode == 0, out.stderr
    lines = [line.split() for line in out.stdout.splitlines()]
    got = [bytes.fromhex(w[1]) for w in lines if len(w) == 2 and w[0] == "FRAME"]
    got = [g for g in got if any(g)]  # the idle padding decodes to zeros
    return got


@pytest.mark.parametrize("depth", [1, 5])
def test_rs_stream(tmp_path, depth):
    frames = _frames(4, 223 * depth, depth)
    assert _deframe(tmp_path, "rs", frames, depth, 0.3, 1) == frames


@pytest.mark.parametrize("depth", [1, 5])
def test_concatenated_stream_with_noise(tmp_path, depth):
    frames = _frames(4, 223 * depth, 10 + depth)
    got = _deframe(tmp_path, "concatenated", frames, depth, 0.45, 2)
    assert got == frames
