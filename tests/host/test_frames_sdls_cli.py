"""`obsw frames keygen`, `sign`, `verify` and `processor --keys`, through the CLI."""

import json
import os

import pytest
from obsw.frames.cltu import decode
from obsw.frames.tc import TcFrame
from obsw_host.cli import main
from obsw_host.frames.links import open_pty_pair

PACKET = "1840c0000002616263"


@pytest.fixture
def key_file(tmp_path, capsys):
    path = str(tmp_path / "tc.keys")
    assert main(["frames", "keygen", path]) == 0
    assert "SA 63: VC 0 MAP 63" in capsys.readouterr().out
    assert os.stat(path).st_mode & 0o777 == 0o600
    return path


def test_sign_then_verify(key_file, capsys):
    assert main(["frames", "sign", "--keys", key_file, PACKET, "--cltu"]) == 0
    cltu = capsys.readouterr().out.strip()
    frame = TcFrame.unpack(decode(bytes.fromhex(cltu))[0], trailing=True)
    assert frame.bypass and frame.data[1:3] == b"\x00\x01"  # SPI 1 after the segment header
    assert main(["frames", "verify", "--keys", key_file, cltu]) == 0
    out = json.loads(capsys.readouterr().out)
    assert (out["outcome"], out["spi"], out["sn"], out["data"]) == ("ok", 1, 1, "c1" + PACKET)
    assert main(["frames", "sign", "--keys", key_file, PACKET, "--map", "63"]) == 0
    frame = bytes.fromhex(capsys.readouterr().out.strip())
    assert frame[6:8] == b"\x00\x3f"  # the essential MAP's own SA
    forged = bytearray(frame)
    forged[12] ^= 1
    forged = TcFrame(0x2A, 0, bytes(forged[5:-2]), 0, True).pack().hex()
    assert main(["frames", "verify", "--keys", key_file, forged]) == 1
    assert json.loads(capsys.readouterr().out)["outcome"] == "bad_mac"
    with open(key_file + ".state") as f:
        assert sorted(json.load(f)) == [[1, 1, 0], [63, 1, 0]]  # numbers kept for the next run


def test_processor_with_keys(key_file, capsys):
    ends = [open_pty_pair() for _ in range(2)]
    try:
        argv = ["frames", "processor", "--uart-a", ends[0][1], "--uart-b", ends[1][1]]
        argv += ["--tm-port", "0", "--playback-port", "0", "--duration", "0.1"]
        assert main(argv + ["--keys", key_file]) == 0
        out = capsys.readouterr().out
        assert "TC security: 2 SA(s)" in out and "events on APID 12" in out
        assert main(argv) == 0
        assert "TC security: off" in capsys.readouterr().out
    finally:
        for fd, _ in ends:
            os.close(fd)


def test_keygen_refuses_to_overwrite_or_write_into_a_repository(key_file, capsys):
    # a user mistake: one line, exit status 2 (as every command's), no traceback
    assert main(["frames", "keygen", key_file]) == 2
    assert "already exists" in capsys.readouterr().err
    assert main(["frames", "keygen", os.path.join(os.path.dirname(__file__), "tc.keys")]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1
