"""CFDP entity processes on loopback UDP (space packets with the CFDP APID): a real file
transferred, and a receiving process killed mid-transfer and started again."""

import os
import subprocess
import sys
import time

import pytest
from mission_ports import free_port, stop
from obsw.cfdp.defs import NO_ERROR
from obsw_host.cfdp.filestore import RootedFilestore
from obsw_host.cfdp.link import UdpEntity, make_entity
from obsw_host.sample import load_sdb

ROOT = os.path.join(os.path.dirname(__file__), "..", "..")
ENV = dict(
    os.environ,
    PYTHONPATH=os.pathsep.join([os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]),
)


def serve(root, port, peer_port):
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "obsw_host.cfdp",
            "serve",
            "--root",
            str(root),
            "--port",
            str(port),
            "--peer",
            "1=127.0.0.1:%d" % peer_port,
            "--id",
            "2",
        ],
        stdout=subprocess.PIPE,
        env=ENV,
        text=True,
    )
    line = proc.stdout.readline()  # the process says it is listening
    assert "cfdp entity 2" in line
    proc.first_line = line
    return proc


def test_put_and_get_between_two_processes(tmp_path):
    onboard_port, ground_port = free_port(), free_port()
    proc = serve(tmp_path / "onboard", onboard_port, ground_port)
    try:
        gnd = tmp_path / "ground"
        gnd.mkdir()
        data = os.urandom(300000)
        (gnd / "up.bin").write_bytes(data)
        common = [
            "--root",
            str(gnd),
            "--port",
            str(ground_port),
            "--peer",
            "2=127.0.0.1:%d" % onboard_port,
            "--timeout",
            "60",
        ]
        put = subprocess.run(
            [
                sys.executable,
                "-m",
                "obsw_host.cfdp",
                "put",
                "up.bin",
                "dir_up.bin",
                "--loss",
                "0.05",
            ]
            + common,
            env=ENV,
            capture_output=True,
            text=True,
            timeout=90,
        )
        assert put.returncode == 0, put.stdout + put.stderr
        assert "delivered up.bin to entity 2" in put.stdout
        assert "retransmitted" in put.stdout
        assert (tmp_path / "onboard" / "dir_up.bin").read_bytes() == data
        get = subprocess.run(
            [sys.executable, "-m", "obsw_host.cfdp", "get", "dir_up.bin", "down.bin"] + common,
            env=ENV,
            capture_output=True,
            text=True,
            timeout=90,
        )
        assert get.returncode == 0, get.stdout + get.stderr
        assert (gnd / "down.bin").read_bytes() == data
    finally:
        stop(proc, grace=0)


@pytest.mark.parametrize("kill_at", [400000])
def test_receiver_killed_mid_transfer_completes_after_restart(tmp_path, kill_at):
    onboard_port, ground_port = free_port(), free_port()
    root = tmp_path / "onboard"
    proc = serve(root, onboard_port, ground_port)
    gfs = RootedFilestore(str(tmp_path / "ground"))
    data = os.urandom(2000000)
    gfs.write_bytes("big.bin", data)
    ent = make_entity(1, [2], gfs, ack_interval=0.5, nak_interval=0.5, limit=60, persist=False)
    udp = UdpEntity(
        ent,
        ("127.0.0.1", ground_port),
        {2: ("127.0.0.1", onboard_port)},
        apid=load_sdb().apid("cfdp"),  # `obsw cfdp serve` runs the sample mission's entity
        rate=2_000_000,
    )
    fin = []
    udp.on_indication = lambda i: fin.append(i.info) if i.kind == "finished" else None
    part_dir = root / ".cfdp"
    restarted = False
    try:
        ent.put(2, "big.bin", "big.bin", now=time.monotonic())
        end = time.monotonic() + 90
        while not fin and time.monotonic() < end:
            udp.step(0.02)
            if not restarted:
                parts = list(part_dir.glob("rx-*.part")) if part_dir.exists() else []
                if parts and parts[0].stat().st_size > kill_at:
                    stop(proc, grace=0)
                    proc = serve(root, onboard_port, ground_port)
                    # the new process picked the transaction up from its persisted state
                    assert "1 transaction(s) restored" in proc.first_line
                    restarted = True
        assert restarted, "the transfer ended before the receiver could be killed"
        assert fin and fin[0]["condition"] == NO_ERROR
        assert (root / "big.bin").read_bytes() == data
    finally:
        udp.close()
        stop(proc, grace=0)
