"""`obsw cfdp` for people, through the real command: sequence numbers that never repeat for an
entity whatever directory a put starts from, one delivered/failed line, a hint when no entity
answers."""

import os
import socket
import subprocess
import sys

from obsw_host.cfdp.client import next_sequence

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
ENV = dict(
    os.environ,
    PYTHONPATH=os.pathsep.join([os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]),
)


def free_ports(n):
    socks = [socket.socket(socket.AF_INET, socket.SOCK_DGRAM) for _ in range(n)]
    for s in socks:
        s.bind(("127.0.0.1", 0))
    ports = [s.getsockname()[1] for s in socks]
    for s in socks:
        s.close()
    return ports


def obsw(*args, cwd=None, env=ENV):
    return subprocess.run(
        [sys.executable, "-m", "obsw_host.cli"] + [str(a) for a in args],
        env=env,
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=60,
    )


def test_sequence_numbers_are_kept_per_entity(tmp_path):
    assert [next_sequence(7, 1, str(tmp_path)) for _ in range(3)] == [1, 2, 3]
    assert next_sequence(8, 1, str(tmp_path)) == 1
    for _ in range(252):
        next_sequence(7, 1, str(tmp_path))
    assert next_sequence(7, 1, str(tmp_path)) == 1  # 255 used: wraps, never 0


def test_puts_from_two_directories_are_both_delivered(tmp_path):
    onboard, ground = free_ports(2)
    sat = tmp_path / "sat"
    server = subprocess.Popen(
        [sys.executable, "-m", "obsw_host.cli", "cfdp", "serve", "--port", str(onboard)]
        + ["--peer", "1=127.0.0.1:%d" % ground, "--root", str(sat)],
        env=ENV,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert "cfdp entity 2 on udp" in server.stdout.readline()  # bound before it says so
        for name in ("one", "two"):
            work = tmp_path / name
            (work / "filestore").mkdir(parents=True)
            (work / "filestore" / "f.bin").write_bytes(os.urandom(5000))
            put = obsw(
                "cfdp", "put", "f.bin", name + ".bin", "--port", ground,
                "--peer", "2=127.0.0.1:%d" % onboard, cwd=work,
            )  # fmt: skip
            assert put.returncode == 0, put.stdout + put.stderr
            assert put.stdout.startswith("delivered f.bin to entity 2: 5000 B")
        assert (sat / "one.bin").read_bytes() == (tmp_path / "one/filestore/f.bin").read_bytes()
        assert (sat / "two.bin").read_bytes() == (tmp_path / "two/filestore/f.bin").read_bytes()
    finally:
        server.terminate()
        server.wait(10)


def test_no_answer_gives_a_hint(tmp_path):
    (port,) = free_ports(1)
    (tmp_path / "filestore").mkdir()
    (tmp_path / "filestore" / "f.bin").write_bytes(b"x" * 100)
    put = obsw(
        "cfdp", "put", "f.bin", "--peer", "2=127.0.0.1:%d" % port, "--answer-timeout", "0.5",
        cwd=tmp_path,
    )  # fmt: skip
    assert put.returncode == 1
    assert put.stderr.strip() == (
        "obsw cfdp: no entity answered at 127.0.0.1:%d within 0.5 s: is `obsw cfdp serve` "
        "(or `obsw obc serve`) running there?" % port
    )
    status = obsw("cfdp", "status", "logs", "--peer", "2=127.0.0.1:%d" % port,
                  "--answer-timeout", "0.5", cwd=tmp_path)  # fmt: skip
    assert status.returncode == 1 and "no entity answered" in status.stderr
