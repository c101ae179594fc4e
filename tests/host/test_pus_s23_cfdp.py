"""Service 23 copies over CFDP on loopback UDP with seeded PDU loss: SAT: -> GROUND: and back
byte-identical; paths outside the filestore root refused with a failure report."""

import pytest
from obsw.pus.messages import FAILURE_PATH
from obsw.pus.services.s23_layouts import COPY_COMPLETED
from storage_demo import Segment


@pytest.fixture
def segment(tmp_path):
    seg = Segment(str(tmp_path), loss=0.1, seed=11, segment=256).start()
    yield seg
    seg.stop()


def test_copy_to_ground_and_back_under_loss(segment):
    sg = segment.sg
    data = bytes((i * 31 + (i >> 7)) & 0xFF for i in range(60000))
    segment.sat_fs.mkdir("science")
    segment.sat_fs.write_bytes("science/a.dat", data)
    sg.copy_reports(2)
    op, tx = sg.copy("SAT:/science/a.dat", "GROUND:/a.dat")
    assert tx.ok, tx.verification()
    st = sg.wait_copy(op, 30.0)
    assert st is not None and st["status"] == COPY_COMPLETED
    assert segment.ground_fs.read_bytes("a.dat") == data
    op2, tx = sg.copy("GROUND:/a.dat", "SAT:/science/back.dat")
    assert tx.ok, tx.verification()
    st = sg.wait_copy(op2, 30.0)
    assert st is not None and st["status"] == COPY_COMPLETED
    assert segment.sat_fs.read_bytes("science/back.dat") == data
    assert segment.sat_udp.dropped + segment.ground_udp.dropped > 0
    assert segment.sat_entity.stats["retransmitted_pdus"] > 0


@pytest.mark.parametrize(
    "source,target",
    [
        ("SAT:/../../etc/passwd", "GROUND:/p"),
        ("SAT:/science/../../x", "GROUND:/x"),
        ("GROUND:/a", "SAT:/../escape"),
    ],
)
def test_paths_outside_the_root_are_refused(segment, source, target):
    op, tx = segment.sg.copy(source, target)
    assert tx.failure is not None
    assert (tx.failure["stage"], tx.failure["code"]) == (2, FAILURE_PATH)
    assert op not in segment.files.ops


def test_file_management_stays_inside_the_root(segment, tmp_path):
    (tmp_path / "secret.txt").write_text("outside")
    sg = segment.sg
    for tx in (sg.attributes("SAT:/../secret.txt"), sg.delete_file("SAT:/../secret.txt")):
        assert tx.failure["code"] == FAILURE_PATH
    assert (tmp_path / "secret.txt").read_text() == "outside"
    segment.sat_fs.write_bytes("inside.txt", b"x")
    tx = sg.attributes("SAT:/inside.txt")
    assert tx.ok and tx.reply["size"] == 1


def test_storage_demo_section():
    from storage_demo import run

    lines = []
    assert run(lines.append)
    text = "\n".join(lines)
    assert "stored HK reports decoded on the ground" in text
    assert "byte-identical on the ground" in text
