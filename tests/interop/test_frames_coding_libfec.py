"""CCSDS 131.0-B channel coding against Debian's libfec (Phil Karn's library), both directions:
RS(255,223) and (255,239) in the dual basis with errors and erasures, the K=7 Viterbi."""

import random

import libfec_peer
import pytest
from obsw.frames import conv, rs, viterbi

fec = libfec_peer.load()
pytestmark = pytest.mark.skipif(fec is None, reason=libfec_peer.reason or "libfec missing")


def _corrupt(block, positions, rnd):
    bad = bytearray(block)
    for p in positions:
        bad[p] ^= rnd.randrange(1, 256)
    return bytes(bad)


@pytest.mark.parametrize("e", [16, 8])
@pytest.mark.parametrize("length", [1, 100, None])
def test_we_encode_libfec_decodes(e, length):
    rnd = random.Random(e * 1000 + (length or 0))
    k = 255 - 2 * e
    n = k if length is None else length
    code = rs.ReedSolomon(e, 1, n)
    for errors in range(e + 1):
        data = bytes(rnd.randrange(256) for _ in range(n))
        block = code.encode(data)
        assert block[n:] == fec.rs_encode(data, e)
        erasures = 2 * e - 2 * errors if n + 2 * e > 2 * e + 1 else 0
        pos = rnd.sample(range(len(block)), min(len(block), errors + erasures))
        word, count = fec.rs_decode(_corrupt(block, pos, rnd), pos[errors:], e)
        assert word == block and count == len(pos)


@pytest.mark.parametrize("e", [16, 8])
@pytest.mark.parametrize("depth", rs.DEPTHS)
def test_libfec_encodes_we_decode(e, depth):
    rnd = random.Random(e * 10 + depth)
    n = 57
    code = rs.ReedSolomon(e, depth, n * depth)
    for errors in (0, 1, e // 2, e):
        words = []
        for _ in range(depth):
            data = bytes(rnd.randrange(256) for _ in range(n))
            words.append(data + fec.rs_encode(data, e))
        block = bytes(words[t % depth][t // depth] for t in range(len(words[0]) * depth))
        erased = []
        pos = []
        for w in range(depth):
            sym = rnd.sample(range(n + 2 * e), errors + 2 * (e - errors))
            pos += [s * depth + w for s in sym[:errors]]
            erased += [s * depth + w for s in sym[errors:]]
        bad = _corrupt(block, pos + erased, rnd)
        frame, fixed = code.decode(bad, erased)
        assert frame == block[: n * depth]
        assert fixed == [errors + 2 * (e - errors)] * depth


def test_uncorrectable_both_say_so():
    rnd = random.Random(5)
    code = rs.ReedSolomon(16)
    data = bytes(rnd.randrange(256) for _ in range(223))
    bad = _corrupt(code.encode(data), rnd.sample(range(255), 17), rnd)
    assert fec.rs_decode(bad)[1] < 0
    with pytest.raises(rs.RsUncorrectableError):
        code.decode(bad)


def test_we_encode_libfec_viterbi_decodes():
    rnd = random.Random(7)
    data = bytes(rnd.randrange(256) for _ in range(500))
    symbols = conv.ConvEncoder().encode(data + b"\x00")  # six zero bits end in state 0
    nbits = len(data) * 8 + 6
    soft = bytearray()
    for b in viterbi.soft_from_bits(symbols)[: 2 * nbits]:
        noise = rnd.gauss(0, 60)
        soft.append(max(0, min(255, int(128 + b + noise))))
    assert fec.viterbi27(soft, nbits) == data


def test_same_noisy_symbols_same_bits_as_libfec():
    # libfec has no encoder: both decoders take the same noisy stream and must agree with
    # the data (and so with each other), our soft convention being signed around zero
    rnd = random.Random(8)
    data = bytes(rnd.randrange(256) for _ in range(400))
    clean = viterbi.soft_from_bits(conv.ConvEncoder().encode(data + b"\x00"), 50)
    nbits = len(data) * 8 + 6
    noisy = [max(-127, min(127, int(s + rnd.gauss(0, 35)))) for s in clean[: 2 * nbits]]
    theirs = fec.viterbi27(bytes(128 + s for s in noisy), nbits)
    v = viterbi.Viterbi27()
    v.reset(0)
    bits = v.feed(noisy) + v.flush()
    ours = bytes(sum(bits[8 * i + k] << (7 - k) for k in range(8)) for i in range(len(data)))
    assert theirs == data
    assert ours == data
