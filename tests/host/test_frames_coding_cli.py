"""`obsw frames tm encode` and `tm decode` with CCSDS 131.0-B coding, files in and out."""

import json
import random
from array import array

import pytest
from obsw.frames.tm import TmFrame
from obsw.frames.viterbi import soft_from_bits
from obsw_host.cli import main


def _frames(n, length=200):
    rnd = random.Random(n)
    return [
        TmFrame(42, 1, bytes(rnd.randrange(256) for _ in range(length - 8)), mc_count=i).pack()
        for i in range(n)
    ]


def _lines(capsys):
    return [json.loads(line) for line in capsys.readouterr().out.splitlines()]


@pytest.mark.parametrize("coding", ["none", "rs", "conv", "concatenated"])
@pytest.mark.parametrize("depth", [1, 2])
def test_encode_decode_files(tmp_path, capsys, coding, depth):
    frames = _frames(3)
    src = tmp_path / "frames.bin"
    src.write_bytes(b"".join(frames))
    coded = tmp_path / "coded.bin"
    args = ["--coding", coding, "--interleave", str(depth), "--rs-e", "8"]
    assert main(["frames", "tm", "encode", "--in", str(src), "--frame-length", "200",
                 "--out", str(coded)] + args) == 0  # fmt: skip
    back = tmp_path / "back.bin"
    assert main(["frames", "tm", "decode", "--in", str(coded), "--frame-length", "200",
                 "--out", str(back)] + args) == 0  # fmt: skip
    lines = _lines(capsys)
    assert [line["mc_count"] for line in lines[:-1]] == [0, 1, 2]
    assert lines[-1]["frames"] == 3 and lines[-1]["uncorrectable"] == 0
    assert back.read_bytes() == b"".join(frames)


def test_hex_file_and_stdout(tmp_path, capsys):
    frame = _frames(1)[0]
    assert main(["frames", "tm", "encode", frame.hex(), "--coding", "rs"]) == 0
    coded = bytes.fromhex(capsys.readouterr().out.strip())
    assert len(coded) == 4 + 200 + 32
    bad = bytearray(coded)
    for i in range(10, 26):  # sixteen symbols wrong: E=16 corrects them
        bad[i] ^= 0xA5
    (tmp_path / "coded.hex").write_text(bad.hex())
    args = ["--in", str(tmp_path / "coded.hex"), "--coding", "rs", "--frame-length", "200"]
    assert main(["frames", "tm", "decode"] + args) == 0
    first, summary = _lines(capsys)
    assert first["rs_corrected"] == [16] and summary["rs_corrected"] == 16
    bad[27] ^= 1
    (tmp_path / "coded.hex").write_text(bad.hex())
    assert main(["frames", "tm", "decode"] + args) == 1
    first, summary = _lines(capsys)
    assert "uncorrectable" in first["error"] and summary["uncorrectable"] == 1


def test_soft_symbols_in(tmp_path, capsys):
    frames = _frames(2)
    src = tmp_path / "f.bin"
    src.write_bytes(b"".join(frames))
    assert main(["frames", "tm", "encode", "--in", str(src), "--frame-length", "200",
                 "--coding", "conv", "--out", str(tmp_path / "c.bin")]) == 0  # fmt: skip
    capsys.readouterr()
    soft = array("b", [-s for s in soft_from_bits((tmp_path / "c.bin").read_bytes(), 90)])
    (tmp_path / "soft.s8").write_bytes(soft.tobytes())  # inverted: the BPSK phase ambiguity
    assert main(["frames", "tm", "decode", "--in", str(tmp_path / "soft.s8"), "--soft",
                 "--format", "bin", "--coding", "conv", "--frame-length", "200"]) == 0  # fmt: skip
    lines = _lines(capsys)
    assert [line["inverted"] for line in lines[:-1]] == [True, True]
    assert [line["mc_count"] for line in lines[:-1]] == [0, 1]


def test_errors_are_one_line(capsys):
    with pytest.raises(SystemExit):
        main(["frames", "tm", "encode", "00", "--coding", "turbo"])
    assert main(["frames", "tm", "decode", "--coding", "rs", "00"]) == 2
    assert "--frame-length" in capsys.readouterr().err
