"""Interop with cfdp-py (PyPI) over loopback UDP, both directions, class 1 and class 2: each
entity behind its own UDP socket (our UdpEntity: one PDU per space packet of the CFDP APID),
real datagrams and real timers, seeded loss on the way out of either side for class 2. The
in-memory tests (test_cfdp_peer.py) cover the protocol cases on a simulated clock; these show
the same transfers survive the real transport. Sockets bind free ports only."""

import os
import subprocess
import sys
import threading
import time

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "core"))
sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "host"))

from cfdp_peer import PeerEntity  # noqa: E402
from cfdp_sim import payload  # noqa: E402
from mission_ports import free_port, stop  # noqa: E402
from obsw.cfdp.defs import DATA_COMPLETE, NO_ERROR  # noqa: E402
from obsw.cfdp.filestore import MemoryFilestore  # noqa: E402
from obsw_host.cfdp.link import UdpEntity, make_entity  # noqa: E402
from obsw_host.sample import load_sdb  # noqa: E402

pytestmark = pytest.mark.filterwarnings("ignore:base is deprecated")

DATA = payload(40000)
SEGMENT = 512
TIMER = 0.5  # s: ACK, NAK and check timers of both sides
DEADLINE = 60.0  # s a transfer may take before the test fails (they take about a second)


def our_entity(mode, files=None):
    return make_entity(
        1,
        [2],
        MemoryFilestore(files or {}),
        mode=mode,
        segment=SEGMENT,
        persist=False,
        ack_interval=TIMER,
        nak_interval=TIMER,
        limit=20,
        keep_alive=TIMER,
    )


class Pair:
    """Our entity 1 and cfdp-py's entity 2, each on a socket of its own bound to a free port."""

    def __init__(self, ours, peer, loss=0.0, seed=1):
        apid = load_sdb().apid("cfdp")
        self.ours = UdpEntity(ours, ("127.0.0.1", 0), {}, apid=apid, loss=loss, seed=seed)
        self.peer = UdpEntity(
            peer, ("127.0.0.1", 0), {}, apid=apid, loss=loss, seed=seed + 1, pace=False
        )
        self.ours.peers[2] = self.peer.address
        self.peer.peers[1] = self.ours.address
        self.finished = []
        self.ours.on_indication = lambda i: i.kind == "finished" and self.finished.append(i.info)

    def run_until(self, done):
        end = time.monotonic() + DEADLINE
        while not done() and time.monotonic() < end:
            self.ours.step(0.01)
            self.peer.step(0.01)
        return done()

    def close(self):
        self.ours.close()
        self.peer.close()


@pytest.fixture
def pairs():
    made = []

    def make(*args, **kw):
        p = Pair(*args, **kw)
        made.append(p)
        return p

    yield make
    for p in made:
        p.close()


def loss_for(mode):
    return 0.05 if mode == 0 else 0.0  # class 2 recovers what UDP loses; class 1 cannot


@pytest.mark.parametrize("mode", [0, 1])
def test_our_udp_sender_to_cfdp_py(tmp_path, pairs, mode):
    ours = our_entity(mode, {"src.bin": DATA})
    peer = PeerEntity(2, 1, mode=mode, segment=SEGMENT, timer=TIMER, limit=20)
    pair = pairs(ours, peer, loss=loss_for(mode), seed=3)
    dst = tmp_path / "dst.bin"
    ours.put(2, "src.bin", str(dst), mode=mode, closure=True, now=time.monotonic())
    assert pair.run_until(lambda: pair.finished and peer.user.finished)
    assert dst.read_bytes() == DATA
    assert pair.finished[0]["condition"] == NO_ERROR
    assert int(peer.user.finished[0].condition_code) == NO_ERROR
    assert int(peer.user.finished[0].delivery_code) == DATA_COMPLETE
    assert pair.ours.sent > len(DATA) // SEGMENT  # every segment went as a datagram
    if mode == 0:
        assert pair.ours.dropped + pair.peer.dropped > 0  # the loss happened and was repaired


@pytest.mark.parametrize("mode", [0, 1])
def test_cfdp_py_sender_to_our_udp_receiver(tmp_path, pairs, mode):
    ours = our_entity(mode)
    peer = PeerEntity(2, 1, mode=mode, segment=SEGMENT, timer=TIMER, limit=20)
    pair = pairs(ours, peer, loss=loss_for(mode), seed=5)
    src = tmp_path / "src.bin"
    src.write_bytes(DATA)
    peer.put(str(src), "dst.bin", closure=True)
    assert pair.run_until(lambda: pair.finished and peer.user.finished)
    assert bytes(ours.fs.files["dst.bin"]) == DATA
    assert pair.finished[0]["condition"] == NO_ERROR
    assert int(peer.user.finished[0].condition_code) == NO_ERROR
    assert pair.ours.received > len(DATA) // SEGMENT
    if mode == 0:
        assert pair.ours.dropped + pair.peer.dropped > 0


ROOT = os.path.join(os.path.dirname(__file__), "..", "..")


def cli(args, tmp_path):
    """``python -m obsw_host.cfdp ARGS`` as a process (its state under ``tmp_path``)."""
    env = dict(
        os.environ,
        OBSW_STATE=str(tmp_path / "state"),
        PYTHONPATH=os.pathsep.join(
            [os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]
        ),
    )
    return subprocess.Popen(
        [sys.executable, "-m", "obsw_host.cfdp"] + args,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        env=env,
        text=True,
    )


class Lines:
    """A process's output lines, read as they come (the test steps its own entity meanwhile)."""

    def __init__(self, proc):
        self.proc = proc
        self.lines = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        for line in self.proc.stdout:
            self.lines.append(line)

    def first(self, prefix):
        return next((x for x in self.lines if x.startswith(prefix)), None)


def peer_alone(peer):
    apid = load_sdb().apid("cfdp")
    return UdpEntity(peer, ("127.0.0.1", 0), {}, apid=apid, pace=False)


def step_until(udp, done):
    end = time.monotonic() + DEADLINE
    while not done() and time.monotonic() < end:
        udp.step(0.01)
    return done()


def test_cfdp_py_sender_to_our_serve_process(tmp_path):
    peer = PeerEntity(1, 2, segment=SEGMENT, timer=TIMER, limit=20)
    udp = peer_alone(peer)
    root = tmp_path / "onboard"
    root.mkdir()
    proc = cli(["serve", "--id", "2", "--port", "0", "--root", str(root),
                "--peer", "1=127.0.0.1:%d" % udp.address[1]], tmp_path)  # fmt: skip
    out = Lines(proc)
    try:
        assert step_until(udp, lambda: out.first("cfdp entity 2 on udp"))
        port = int(out.first("cfdp entity 2 on udp").split(",")[0].rsplit(":", 1)[1])
        udp.peers[2] = ("127.0.0.1", port)
        src = tmp_path / "src.bin"
        src.write_bytes(DATA)
        peer.put(str(src), "dst.bin", closure=True)
        assert step_until(udp, lambda: peer.user.finished and out.first("finished"))
        assert "condition=0" in out.first("finished"), out.lines
        assert int(peer.user.finished[0].condition_code) == NO_ERROR
        assert (root / "dst.bin").read_bytes() == DATA
    finally:
        stop(proc, grace=0)
        udp.close()


def test_our_put_process_to_cfdp_py(tmp_path):
    peer = PeerEntity(2, 1, segment=SEGMENT, timer=TIMER, limit=20)
    udp = peer_alone(peer)
    ground = tmp_path / "ground"
    ground.mkdir()
    (ground / "up.bin").write_bytes(DATA)
    dst = tmp_path / "up.bin"
    port = free_port()  # the put's own port, for cfdp-py to answer to
    udp.peers[1] = ("127.0.0.1", port)
    proc = cli(["put", "up.bin", str(dst), "--id", "1", "--port", str(port), "--root", str(ground),
                "--peer", "2=127.0.0.1:%d" % udp.address[1], "--segment", str(SEGMENT),
                "--timeout", str(DEADLINE)], tmp_path)  # fmt: skip
    out = Lines(proc)
    try:
        assert step_until(udp, lambda: proc.poll() is not None and peer.user.finished)
        assert proc.returncode == 0, out.lines
        assert dst.read_bytes() == DATA
        assert int(peer.user.finished[0].condition_code) == NO_ERROR
    finally:
        stop(proc, grace=0)
        udp.close()
