"""Services 6 (6,1 .. 6,22), 15 (15,24, diagnostic storage), 21 (21,2, 21,8) and 22 (22,28)
against spacepackets, both ways, byte for byte: the TCs our users send decode in spacepackets
to the application data a ground tool packs by hand with struct; TCs spacepackets builds from
such data are served; our reports decode in spacepackets and read field for field by hand.
(spacepackets and puslib define none of these message types' layouts, only the packets.)"""

import asyncio
import struct
import sys
from pathlib import Path

from spacepackets.ecss.tc import PusTc as SpTc
from spacepackets.ecss.tm import PusTm as SpTm

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "core"))

from obsw.cfdp.filestore import MemoryFilestore  # noqa: E402
from obsw.crc import crc16_ccitt  # noqa: E402
from obsw.pus.messages import FAILURE_REFUSED  # noqa: E402
from obsw.pus.parameters import ParameterPool  # noqa: E402
from obsw.pus.sdb import loads  # noqa: E402
from obsw.pus.services.s06_memory import BytesMemory, MemoryManagement, MemoryUser  # noqa: E402
from obsw.pus.services.s15_storage import Storage  # noqa: E402
from obsw.pus.services.s15_user import StorageUser  # noqa: E402
from obsw.pus.services.s17_test import ServiceTest, ServiceTestUser  # noqa: E402
from obsw.pus.services.s21_sequencing import (  # noqa: E402
    RequestSequencing,
    RequestSequencingUser,
)
from obsw.pus.services.s22_position_scheduling import (  # noqa: E402
    PositionScheduling,
    PositionSchedulingUser,
)
from obsw.pus.services.s23_files import FileManagement  # noqa: E402
from pus_loop import APID, Loop  # noqa: E402

SDB = """{"apids": {"pus": 10},
  "parameters": [{"name": "orbit", "id": 100, "type": "uint32", "writable": true}]}"""


def s(text):
    """A repository or file name as the TCs carry it: 16-bit length, then the characters."""
    return struct.pack(">H", len(text)) + text.encode()


def make():
    fs = MemoryFilestore({"up/p.bin": b"PQ", "up/w.seq": b""})
    fs.dirs.update(("up", "down"))
    loop = Loop()
    loop.clock.advance(2_100_000_000)
    app = loop.app
    pool = ParameterPool(loads(SDB))
    areas = {1: BytesMemory(64, 0x1000, True, bytes(range(64)), {3: ("table", 8, 16)})}
    app.register(MemoryManagement(areas))
    app.register(FileManagement(fs))
    app.register(Storage(filestore=MemoryFilestore()))
    app.register(ServiceTest())
    app.register(RequestSequencing())
    app.register(PositionScheduling(pool, "orbit"))
    users = {
        6: loop.ground.register(MemoryUser()),
        15: loop.ground.register(StorageUser()),
        17: loop.ground.register(ServiceTestUser()),
        21: loop.ground.register(RequestSequencingUser()),
        22: loop.ground.register(PositionSchedulingUser()),
    }
    return loop, fs, pool, users


def sent(loop, tx):
    """Pump ``tx`` through; (spacepackets' decoding of the TC, the transaction)."""
    loop.pump()
    return SpTc.unpack(loop.tc[-1]), tx


CRC_PQ = crc16_ccitt(b"PQ")


def our_tcs():
    """(service, subtype, the application data packed by hand, what our user sent)."""
    loop, fs, pool, u = make()
    m, st, sq = u[6], u[15], u[21]
    ping = u[17]
    seq_file = sq.sequence_file([(sq.embed(APID, 17, 1)[1], 0.5)])
    fs.write_bytes("up/w.seq", seq_file)
    cases = [
        (
            6,
            1,
            struct.pack(">HHBI", 1, 3, 1, 2) + b"\x00\x02PQ" + struct.pack(">H", CRC_PQ),
            lambda: m.load_object(APID, 1, 3, 2, b"PQ"),
        ),
        (6, 3, struct.pack(">HHBII", 1, 3, 1, 0, 4), lambda: m.dump_object(APID, 1, 3, [(0, 4)])),
        (6, 7, struct.pack(">HHBII", 1, 3, 1, 4, 4), lambda: m.check_object(APID, 1, 3, [(4, 4)])),
        (
            6,
            11,
            struct.pack(">HI", 1, 0x1000) + b"\x00\x02PQ" + struct.pack(">H", CRC_PQ),
            lambda: m.load_atomic(APID, 1, 0x1000, b"PQ"),
        ),
        (6, 12, b"", lambda: m.abort_dumps(APID)),
        (6, 13, b"\x00\x01", lambda: m.enable_scrubbing(APID, 1)),
        (6, 14, b"\x00\x01", lambda: m.disable_scrubbing(APID, 1)),
        (6, 15, b"\x00\x01", lambda: m.protect(APID, 1)),
        (6, 16, b"\x00\x01", lambda: m.unprotect(APID, 1)),
        (6, 17, b"\x00\x01\x00\x03", lambda: m.check_whole_object(APID, 1, 3)),
        (
            6,
            19,
            struct.pack(">HBI", 1, 1, 0x1010)
            + s("SAT:/up")
            + s("p.bin")
            + struct.pack(">H", CRC_PQ),
            lambda: m.load_by_reference(APID, 1, [(0x1010, "SAT:/up/p.bin", CRC_PQ)]),
        ),
        (
            6,
            20,
            struct.pack(">HBII", 1, 1, 0x1000, 8) + s("SAT:/down") + s("r.bin"),
            lambda: m.dump_to_file(APID, 1, [(0x1000, 8, "SAT:/down/r.bin")]),
        ),
        (
            6,
            21,
            struct.pack(">HHBI", 1, 3, 1, 6)
            + s("SAT:/up")
            + s("p.bin")
            + struct.pack(">H", CRC_PQ),
            lambda: m.load_object_by_reference(APID, 1, 3, [(6, "SAT:/up/p.bin", CRC_PQ)]),
        ),
        (
            6,
            22,
            struct.pack(">HHBII", 1, 3, 1, 0, 16) + s("SAT:/down") + s("o.bin"),
            lambda: m.dump_object_to_file(APID, 1, 3, [(0, 16, "SAT:/down/o.bin")]),
        ),
        (
            15,
            20,
            None,
            lambda: st.create(
                APID,
                [
                    {"store": 1, "size": 900, "kind": 0, "vc": 0},
                    {"store": 2, "size": 900, "kind": 0, "vc": 0},
                ],
            ),
        ),
        (15, 3, None, lambda: st.add_types(APID, 1, {APID: {17: [2]}})),
        (15, 1, None, lambda: st.enable(APID, [1])),
        (17, 1, None, lambda: ping.ping(APID)),
        (
            15,
            24,
            struct.pack(">BIHIHHH", 0, 0, 0, 2_200_000_000, 0x8000, 1, 2),
            lambda: st.copy_window(APID, 1, 2, 0, 2_200_000_000.5),
        ),
        (15, 32, struct.pack(">HBHB", 1, 1, APID, 0), lambda: st.delete_diag(APID, 1, {APID: []})),
        (
            15,
            31,
            struct.pack(">HBHBHH", 1, 1, APID, 2, 5, 6),
            lambda: st.add_diag(APID, 1, {APID: [5, 6]}),
        ),
        (15, 37, b"\x00\x01", lambda: st.report_diag(APID, 1)),
        (
            21,
            2,
            b"\x01w" + s("SAT:/up") + s("w.seq"),
            lambda: sq.load_by_reference(APID, "w", "SAT:/up/w.seq"),
        ),
        (
            21,
            8,
            b"\x01v" + s("SAT:/up") + s("w.seq"),
            lambda: sq.load_and_activate(APID, "v", "SAT:/up/w.seq"),
        ),
        (22, 28, struct.pack(">I", 4321), lambda: u[22].set_orbit(APID, 4321)),
    ]
    out = []
    for service, subtype, data, make_tx in cases:
        sp, tx = sent(loop, make_tx())
        loop.clock.advance(1.0)
        loop.app.tick()
        loop.pump()
        out.append((service, subtype, data, sp, tx))
    return loop, fs, pool, out


RUN = None


def run():
    global RUN
    if RUN is None:
        RUN = our_tcs()
    return RUN


def test_our_tcs_decode_in_spacepackets_to_hand_packed_data():
    loop, fs, pool, cases = run()
    n = 0
    for service, subtype, data, sp, tx in cases:
        assert (sp.service, sp.message_subtype) == (service, subtype)
        assert (sp.apid, sp.source_id) == (APID, 7)
        if data is not None:
            assert sp.app_data == data, (service, subtype)
            n += 1
        assert tx.ok, (service, subtype, tx.failure)
    assert n == 21


def test_what_they_did_on_board():
    loop, fs, pool, cases = run()
    mem = loop.app.services[6].areas[1]
    assert bytes(mem.buf[0:2]) == b"PQ"  # 6,11
    assert bytes(mem.buf[16:18]) == b"PQ"  # 6,19 at 0x1010
    assert bytes(mem.buf[8 + 2 : 8 + 4]) == b"PQ"  # 6,1 at object 3, offset 2
    assert bytes(mem.buf[8 + 6 : 8 + 8]) == b"PQ"  # 6,21 at object 3, offset 6
    assert bytes(fs.files["down/r.bin"]) == bytes(mem.buf[0:8])
    assert bytes(fs.files["down/o.bin"]) == bytes(mem.buf[8:24])
    st = loop.app.services[15]
    assert len(st.stores[2].packets) == 1  # the TM[17,2] copied
    assert loop.app.services[21].sequences["v"].active is False  # ran to its end
    assert pool.get(100) == 4321


def _reports(loop, service, subtype):
    out = []
    for raw in loop.raw:
        sp = SpTm.unpack(raw, timestamp_len=6)
        if (sp.service, sp.message_subtype) == (service, subtype):
            out.append(sp.source_data)
    assert out, (service, subtype)
    return out


def test_our_reports_decode_in_spacepackets():
    loop, fs, pool, cases = run()
    # object 3 (octets 8..24) when it was dumped and checked: as made, PQ loaded at offset 2
    table = bytearray(range(8, 24))
    table[2:4] = b"PQ"
    table = bytes(table)
    (d,) = _reports(loop, 6, 4)
    assert d == struct.pack(">HHBI", 1, 3, 1, 0) + b"\x00\x04" + table[:4] + struct.pack(
        ">H", crc16_ccitt(table[:4])
    )
    (d,) = _reports(loop, 6, 8)
    assert d == struct.pack(">HHBIIH", 1, 3, 1, 4, 4, crc16_ccitt(table[4:8]))
    (d,) = _reports(loop, 6, 18)
    assert d == struct.pack(">HHIH", 1, 3, 16, crc16_ccitt(table))
    (d,) = _reports(loop, 15, 38)
    assert d == struct.pack(">HBHBHH", 1, 1, APID, 2, 5, 6)


def test_tcs_built_by_spacepackets_are_served():
    loop, fs, pool, users = make()
    app = loop.app
    asyncio.run(asyncio.sleep(0))

    def serve(service, subtype, data, seq):
        tc = SpTc(
            service=service, message_subtype=subtype, apid=APID, seq_count=seq, app_data=data
        )
        app.receive(tc.pack())
        loop.pump()
        rep = SpTm.unpack(loop.raw[-1], timestamp_len=6)
        return rep.service, rep.message_subtype

    assert serve(
        6, 11, struct.pack(">HI", 1, 0x1020) + b"\x00\x02PQ" + struct.pack(">H", CRC_PQ), 1
    ) == (1, 7)
    assert bytes(app.services[6].areas[1].buf[32:34]) == b"PQ"
    assert serve(6, 15, b"\x00\x01", 2) == (1, 7)
    assert serve(
        6,
        2,
        struct.pack(">HBI", 1, 1, 0x1000) + b"\x00\x01x" + struct.pack(">H", crc16_ccitt(b"x")),
        3,
    ) == (1, 4)
    assert serve(6, 16, b"\x00\x01", 4) == (1, 7)
    assert serve(6, 17, b"\x00\x01\x00\x00", 5) == (1, 7)
    d = SpTm.unpack(loop.raw[-2], timestamp_len=6).source_data
    assert d == struct.pack(">HHIH", 1, 0, 64, crc16_ccitt(bytes(app.services[6].areas[1].buf)))
    assert serve(
        6,
        19,
        struct.pack(">HBI", 1, 1, 0x1030) + s("SAT:/up") + s("p.bin") + struct.pack(">H", CRC_PQ),
        6,
    ) == (1, 7)
    assert bytes(app.services[6].areas[1].buf[48:50]) == b"PQ"
    fs.write_bytes("up/w.seq", users[21].sequence_file([(users[21].embed(APID, 17, 1)[1], 0)]))
    assert serve(21, 8, b"\x01z" + s("SAT:/up") + s("w.seq"), 7) == (1, 7)
    assert app.services[21].sequences["z"].active
    assert serve(22, 28, struct.pack(">I", 77), 8) == (1, 7)
    assert pool.get(100) == 77
    assert serve(15, 20, struct.pack(">BHIBBHIBB", 2, 1, 900, 0, 0, 2, 900, 0, 0), 9) == (1, 7)
    assert serve(15, 24, struct.pack(">BIHIHHH", 0, 0, 0, 5, 0, 1, 2), 10) == (1, 7)
    # a time window type the standard does not define: refused at the start (TM[1,4])
    assert serve(15, 24, struct.pack(">BIHIHHH", 9, 0, 0, 0, 0, 1, 2), 11) == (1, 4)
    d = SpTm.unpack(loop.raw[-1], timestamp_len=6).source_data
    assert (d[4], d[5:]) == (FAILURE_REFUSED, b"\x00\x01")
