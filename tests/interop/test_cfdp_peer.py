"""Interop with cfdp-py (PyPI) as the other CFDP entity, both directions, class 1 and class 2,
with seeded loss, duplication and reordering; PDUs handed over in memory on a simulated clock."""

import os
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "core"))

from cfdp_peer import PeerEntity, use_sim_clock  # noqa: E402
from cfdp_sim import Link, payload  # noqa: E402
from obsw.cfdp.defs import DATA_COMPLETE, FILE_RETAINED, NO_ERROR  # noqa: E402
from obsw.cfdp.entity import CfdpEntity  # noqa: E402
from obsw.cfdp.filestore import MemoryFilestore  # noqa: E402
from obsw.cfdp.mib import Mib, RemoteEntity  # noqa: E402
from obsw.crc import CHECKSUM_CRC32, CHECKSUM_CRC32C, CHECKSUM_MODULAR, CHECKSUM_NULL  # noqa: E402
from spacepackets.cfdp import ChecksumType  # noqa: E402

pytestmark = pytest.mark.filterwarnings("ignore:base is deprecated")

DATA = payload(5000)
CHECKSUMS = {
    CHECKSUM_CRC32: ChecksumType.CRC_32,
    CHECKSUM_CRC32C: ChecksumType.CRC_32C,
    CHECKSUM_MODULAR: ChecksumType.MODULAR,
    CHECKSUM_NULL: ChecksumType.NULL_CHECKSUM,
}


def ours(files=None, mode=0, checksum=CHECKSUM_CRC32):
    remote = RemoteEntity(
        2,
        mode=mode,
        checksum=checksum,
        max_segment=64,
        ack_interval=2.0,
        nak_interval=2.0,
        ack_limit=10,
        nak_limit=10,
        closure=True,
    )
    return CfdpEntity(Mib(1, [remote]), MemoryFilestore(files or {}))


def link_kw(mode, seed):
    if mode == 1:  # class 1 cannot recover losses: duplicates only
        return {"seed": seed, "dup": 0.1}
    return {"seed": seed, "loss": 0.1, "dup": 0.05, "reorder": 0.1}


def agree(test_fin, peer_fin):
    """Our view of the Finished PDU and cfdp-py's agree."""
    assert test_fin["condition"] == int(peer_fin.condition_code) == NO_ERROR
    assert test_fin["delivery"] == int(peer_fin.delivery_code) == DATA_COMPLETE
    assert test_fin["file_status"] == int(peer_fin.file_status) == FILE_RETAINED


@pytest.mark.parametrize("mode", [0, 1])
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_our_sender_to_peer_receiver(tmp_path, monkeypatch, mode, seed):
    a = ours({"src.bin": DATA}, mode)
    peer = PeerEntity(2, 1, mode=mode)
    link = Link(a, peer, **link_kw(mode, seed))
    use_sim_clock(monkeypatch, link)
    dst = tmp_path / "dst.bin"
    a.put(2, "src.bin", str(dst), mode=mode, closure=True)
    assert link.run(max_time=2000)
    assert dst.read_bytes() == DATA
    agree(link.finished(0)[0].info, peer.user.finished[0])
    assert a.tx == {}


@pytest.mark.parametrize("mode", [0, 1])
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_peer_sender_to_our_receiver(tmp_path, monkeypatch, mode, seed):
    b = ours(mode=mode)
    src = tmp_path / "src.bin"
    src.write_bytes(DATA)
    peer = PeerEntity(2, 1, mode=mode)
    link = Link(peer, b, **link_kw(mode, seed))
    use_sim_clock(monkeypatch, link)
    peer.put(str(src), "dst.bin", closure=True)
    assert link.run(max_time=2000)
    assert bytes(b.fs.files["dst.bin"]) == DATA
    agree(link.finished(1)[0].info, peer.user.finished[0])
    assert b.tx == {}


@pytest.mark.parametrize("ours_ck", sorted(CHECKSUMS))
def test_checksum_types_both_ways(tmp_path, monkeypatch, ours_ck):
    a = ours({"src.bin": DATA}, 0, ours_ck)
    peer = PeerEntity(2, 1, checksum=CHECKSUMS[ours_ck])
    link = Link(a, peer, seed=9, loss=0.05)
    use_sim_clock(monkeypatch, link)
    a.put(2, "src.bin", str(tmp_path / "in.bin"))
    (tmp_path / "out.bin").write_bytes(DATA)
    peer.put(str(tmp_path / "out.bin"), "out.bin", closure=True)
    assert link.run(max_time=2000)
    assert (tmp_path / "in.bin").read_bytes() == DATA
    assert bytes(a.fs.files["out.bin"]) == DATA
    assert [f.info["condition"] for f in link.finished(0)] == [NO_ERROR, NO_ERROR]


def test_empty_file_both_ways(tmp_path, monkeypatch):
    a = ours({"empty": b""})
    peer = PeerEntity(2, 1)
    link = Link(a, peer)
    use_sim_clock(monkeypatch, link)
    a.put(2, "empty", str(tmp_path / "e1"))
    (tmp_path / "e2").write_bytes(b"")
    peer.put(str(tmp_path / "e2"), "e2", closure=True)
    assert link.run(max_time=500)
    assert (tmp_path / "e1").read_bytes() == b""
    assert bytes(a.fs.files["e2"]) == b""


def test_lossy_acks_and_finished_both_directions(tmp_path, monkeypatch):
    """Loss on every kind of PDU, both ways, several files in a row: nothing stalls."""
    for seed in (21, 22, 23, 24):
        a = ours({"src.bin": DATA})
        peer = PeerEntity(2, 1)
        link = Link(a, peer, seed=seed, loss=0.2, reorder=0.1)
        use_sim_clock(monkeypatch, link)
        dst = tmp_path / ("d%d" % seed)
        a.put(2, "src.bin", str(dst))
        assert link.run(max_time=5000)
        assert dst.read_bytes() == DATA
        assert link.finished(0)[0].info["condition"] == NO_ERROR
