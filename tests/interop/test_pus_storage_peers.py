"""Every TM of services 2, 4, 6, 13, 14, 15 and 23 decoded by spacepackets (header and
source data), and its source data read field for field independently of our layouts; every
TC our service users sent decoded by spacepackets."""

import asyncio
import struct
import sys
from pathlib import Path

from spacepackets.ecss.tc import PusTc as SpTc
from spacepackets.ecss.tm import PusTm as SpTm

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "core"))

from obsw.cfdp.filestore import MemoryFilestore  # noqa: E402
from obsw.crc import crc16_ccitt  # noqa: E402
from obsw.pus.parameters import ParameterPool  # noqa: E402
from obsw.pus.services.s04_statistics import ParameterStatistics, StatisticsUser  # noqa: E402
from obsw.pus.services.s06_memory import BytesMemory, MemoryManagement, MemoryUser  # noqa: E402
from obsw.pus.services.s13_large_packets import (  # noqa: E402
    LargePacketTransfer,
    LargePacketUser,
)
from obsw.pus.services.s14_forwarding import ForwardingControl, ForwardingUser  # noqa: E402
from obsw.pus.services.s15_storage import Storage  # noqa: E402
from obsw.pus.services.s15_user import StorageUser  # noqa: E402
from obsw.pus.services.s17_test import ServiceTest, ServiceTestUser  # noqa: E402
from pus_loop import APID, Loop, sdb  # noqa: E402
from test_pus_s02_device_access import PACKETS, RAW, Bench  # noqa: E402
from test_pus_s23_files import make as files_make  # noqa: E402


def services_scenario():
    db = sdb()
    loop = Loop()
    loop.clock.advance(2_100_000_000)
    app, ground = loop.app, loop.ground
    pool = ParameterPool(db)
    pool.values.update({1: 12.5, 3: 2})
    app.register(ServiceTest())
    app.register(ParameterStatistics(pool))
    app.register(MemoryManagement({1: BytesMemory(64, 0x1000, True, bytes(range(64)))}))
    large = app.register(LargePacketTransfer(part_size=20, parts_per_cycle=None))
    app.register(ForwardingControl())
    app.register(Storage(filestore=MemoryFilestore(), rate=50))
    types = lambda pid: db.parameter(pid).type  # noqa: E731
    st4 = ground.register(StatisticsUser(types))
    st6 = ground.register(MemoryUser())
    st13 = ground.register(LargePacketUser(part_size=20))
    st14 = ground.register(ForwardingUser())
    st15 = ground.register(StorageUser())
    st17 = ground.register(ServiceTestUser())
    for make in (
        lambda: st4.add_definitions(APID, {1: 1, 3: 1}),
        lambda: st4.enable_periodic(APID, 2),
        lambda: st4.report_definitions(APID),
        lambda: st6.load(APID, 1, 0x1004, b"\xaa\xbb"),
        lambda: st6.dump(APID, 1, [(0x1000, 8), (0x1010, 3)]),
        lambda: st6.check(APID, 1, [(0x1000, 64)]),
        lambda: st14.add_types(APID, {APID: {}, 33: {3: [25], 5: []}}),
        lambda: st14.add_hk(APID, {33: [4, 5]}),
        lambda: st14.add_blocked(APID, {APID: [3, 4]}),
        lambda: st14.report_types(APID),
        lambda: st14.report_hk(APID),
        lambda: st14.report_blocked(APID),
        lambda: st15.create(APID, [{"store": 1, "size": 5000, "kind": 0, "vc": 1}]),
        lambda: st15.create(APID, [{"store": 2, "size": 300, "kind": 1, "vc": 2}]),
        lambda: st15.add_types(APID, 1, {APID: {17: [2], 4: []}}),
        lambda: st15.delete_hk(APID, 1, {APID: []}),
        lambda: st15.add_hk(APID, 1, {APID: [1]}),
        lambda: st15.add_blocked(APID, 1, {APID: [9]}),
        lambda: st15.enable(APID, [1]),
        lambda: st17.ping(APID),
        lambda: st17.ping(APID),
        lambda: st15.report_types(APID, 1),
        lambda: st15.report_hk(APID, 1),
        lambda: st15.report_blocked(APID, 1),
        lambda: st15.report_summary(APID),
        lambda: st15.report_status(APID),
        lambda: st15.report_configuration(APID),
        lambda: st15.retrieve_sequence(APID, 1, 1, 2),
        lambda: st15.retrieve_time(APID, 1, 0, 2**32 - 1),
    ):
        make()
        loop.pump()
        loop.clock.advance(1.0)
        app.tick()
        loop.pump()
    st4.report(APID, reset=True)
    st13.uplink(APID, bytes(range(50)))
    loop.pump()
    large.downlink(bytes(range(70)))
    st13.send_part(APID, 1, 77, 2, b"x")  # out of sequence: TM[13,16]
    loop.pump()
    return loop


def files_scenario():
    fl = files_make(max_segment=128)
    fl.loop.clock.advance(2_100_000_000)
    u = fl.user
    fl.run(lambda: u.create(APID, "SAT:/data/new.txt", 100))
    fl.run(lambda: u.attributes(APID, "SAT:/data/a.bin"))
    fl.run(lambda: u.find(APID, "SAT:/", "*.bin"))
    fl.run(lambda: u.summary(APID, "SAT:/data"))
    fl.run(lambda: u.enable_reports(APID, 2))
    fl.run(
        lambda: u.copy(APID, 3, "SAT:/data/a.bin", "GROUND:/a.bin"),
        until=lambda: fl.files.ops[3]["status"] == 3,
    )
    fl.run(lambda: u.copy(APID, 4, "SAT:/../x", "GROUND:/x"))
    return fl.loop


def device_scenario():
    b = Bench()
    b.loop.clock.advance(2_100_000_000)
    b.run(lambda: b.user.acquire(APID, [(RAW, b"?q")]))
    b.run(lambda: b.user.logical_acquire(APID, [(PACKETS, 17, 1, b"")]))
    b.run(lambda: b.user.command(APID, [(RAW, b"\x01")]))
    b.run(lambda: b.user.logical_command(APID, [(PACKETS, 17, 1, b"")]))
    return b.loop


LOOPS = None


def loops():
    global LOOPS
    if LOOPS is None:
        LOOPS = [services_scenario(), files_scenario(), device_scenario()]
    return LOOPS


def all_tm():
    return [(raw, tm) for lp in loops() for raw, tm in zip(lp.raw, lp.tm)]


class Reader:
    """Reads big-endian fields from source data, the way a ground tool would by hand."""

    def __init__(self, data):
        self.d = data
        self.i = 0

    def take(self, fmt):
        v = struct.unpack_from(">" + fmt, self.d, self.i)
        self.i += struct.calcsize(">" + fmt)
        return v[0] if len(v) == 1 else v

    def octets(self):
        n = self.take("H")
        v = self.d[self.i : self.i + n]
        self.i += n
        return v

    def text(self):
        return self.octets().decode()

    def done(self):
        assert self.i == len(self.d), (self.i, len(self.d))


def test_scenarios_cover_every_report_type():
    kinds = {(t.service, t.subtype) for _, t in all_tm()}
    expected = {
        (2, 9), (2, 12), (4, 2), (4, 9), (6, 6), (6, 10), (13, 1), (13, 2), (13, 3),
        (13, 16), (14, 4), (14, 8), (14, 16), (15, 6), (15, 13), (15, 19), (15, 23),
        (15, 36), (15, 40), (23, 4), (23, 8), (23, 13), (23, 23),
    }  # fmt: skip
    assert expected <= kinds, expected - kinds


def test_every_tm_decodes_in_spacepackets():
    tms = all_tm()
    assert len(tms) > 100
    for raw, ours in tms:
        sp = SpTm.unpack(raw, timestamp_len=6)
        assert (sp.apid, sp.seq_count, sp.service, sp.message_subtype) == (
            ours.apid,
            ours.seq_count,
            ours.service,
            ours.subtype,
        )
        sec = sp.pus_tm_sec_header
        assert sec.message_counter == ours.message_counter
        assert sec.dest_id == ours.destination_id
        assert sec.timestamp == struct.pack(">IH", *ours.time)
        assert sp.source_data == ours.data


def _data(service, subtype):
    out = []
    for raw, _ours in all_tm():
        sp = SpTm.unpack(raw, timestamp_len=6)
        if (sp.service, sp.message_subtype) == (service, subtype):
            out.append(sp.source_data)
    assert out, (service, subtype)
    return out


def test_device_reports():
    (d,) = _data(2, 9)
    r = Reader(d)
    assert r.take("B") == 1
    assert (r.take("H"), r.octets()) == (RAW, b"Rq")
    r.done()
    (d,) = _data(2, 12)
    r = Reader(d)
    assert r.take("B") == 1
    assert (r.take("H"), r.take("B"), r.take("B"), r.octets()) == (PACKETS, 17, 2, b"")
    r.done()


def _time(r):
    coarse, fine = r.take("IH")
    return coarse + fine / 65536


def test_statistics_reports():
    for d in _data(4, 2):
        r = Reader(d)
        start, end = _time(r), _time(r)
        assert start <= end
        assert r.take("H") == 2
        assert r.take("H") == 1  # Panel.angle, float32
        n = r.take("I")
        mx, _, mn, _ = r.take("f"), _time(r), r.take("f"), _time(r)
        mean, sd = r.take("d"), r.take("d")
        if n:
            assert (mx, mn, mean, sd) == (12.5, 12.5, 12.5, 0.0)
        assert r.take("H") == 3  # Panel.mode, uint8
        r.take("I")
        r.take("B")
        _time(r)
        r.take("B")
        _time(r)
        r.take("dd")
        r.done()
    (d,) = _data(4, 9)
    r = Reader(d)
    assert (r.take("H"), r.take("H")) == (2, 2)
    assert [r.take("HH") for _ in range(2)] == [(1, 1), (3, 1)]
    r.done()


def test_memory_reports():
    (d,) = _data(6, 6)
    r = Reader(d)
    assert (r.take("H"), r.take("B")) == (1, 2)
    a, data, crc = r.take("I"), r.octets(), r.take("H")
    assert (a, data) == (0x1000, bytes([0, 1, 2, 3, 0xAA, 0xBB, 6, 7]))
    assert crc == crc16_ccitt(data)
    assert (r.take("I"), r.octets()) == (0x1010, bytes([16, 17, 18]))
    r.take("H")
    r.done()
    (d,) = _data(6, 10)
    r = Reader(d)
    assert (r.take("H"), r.take("B"), r.take("I"), r.take("I")) == (1, 1, 0x1000, 64)
    mem = bytearray(range(64))
    mem[4:6] = b"\xaa\xbb"
    assert r.take("H") == crc16_ccitt(bytes(mem))
    r.done()


def test_large_packet_reports():
    parts = []
    for sub in (1, 2, 3):
        for d in _data(13, sub):
            r = Reader(d)
            _tid, seq, part = r.take("H"), r.take("H"), r.octets()
            r.done()
            parts.append((seq, part))
    assert b"".join(p for _, p in sorted(parts)) == bytes(range(70))
    (d,) = _data(13, 16)
    r = Reader(d)
    assert (r.take("H"), r.take("B")) == (77, 2)
    r.done()


def _types(r):
    out = {}
    for _ in range(r.take("B")):
        apid = r.take("H")
        services = {}
        for _ in range(r.take("B")):
            s = r.take("B")
            services[s] = [r.take("B") for _ in range(r.take("B"))]
        out[apid] = services
    return out


def test_forwarding_reports():
    (d,) = _data(14, 4)
    r = Reader(d)
    assert _types(r) == {APID: {}, 33: {3: [25], 5: []}}
    r.done()
    (d,) = _data(14, 8)
    r = Reader(d)
    assert r.take("B") == 2
    assert (r.take("H"), r.take("B")) == (APID, 0)
    assert (r.take("H"), r.take("B"), r.take("H"), r.take("H")) == (33, 2, 4, 5)
    r.done()
    (d,) = _data(14, 16)
    r = Reader(d)
    assert r.take("H") == 2
    assert [r.take("HH") for _ in range(2)] == [(APID, 3), (APID, 4)]
    r.done()


def test_storage_reports():
    (d,) = _data(15, 6)
    r = Reader(d)
    assert r.take("H") == 1
    assert _types(r) == {APID: {4: [], 17: [2]}}
    r.done()
    (d,) = _data(15, 13)
    r = Reader(d)
    assert r.take("B") == 2
    assert r.take("H") == 1
    oldest, newest, _open = _time(r), _time(r), _time(r)
    assert oldest <= newest
    fill, fill_open, count, first, last = (
        r.take("B"),
        r.take("B"),
        r.take("I"),
        r.take("I"),
        r.take("I"),
    )
    assert (count, first) == (last, 1) and 0 < fill <= 100 and fill_open <= fill + 1
    assert r.take("H") == 2
    r.take("IHIHIHBBIII")
    r.done()
    (d,) = _data(15, 19)
    r = Reader(d)
    assert r.take("B") == 2
    assert [r.take("HBBB") for _ in range(2)] == [(1, 1, 0, 0), (2, 0, 0, 0)]
    r.done()
    (d,) = _data(15, 23)
    r = Reader(d)
    assert r.take("B") == 2
    assert [r.take("HIBB") for _ in range(2)] == [(1, 5000, 0, 1), (2, 300, 1, 2)]
    r.done()
    (d,) = _data(15, 36)
    r = Reader(d)
    assert (r.take("H"), r.take("B"), r.take("H"), r.take("B"), r.take("H")) == (1, 1, APID, 1, 1)
    r.done()
    (d,) = _data(15, 40)
    r = Reader(d)
    assert (r.take("H"), r.take("H"), r.take("H"), r.take("H")) == (1, 1, APID, 9)
    r.done()


def test_storage_playback_is_the_stored_packets():
    loop = loops()[0]
    pings = [raw for raw, tm in zip(loop.raw, loop.tm) if (tm.service, tm.subtype) == (17, 2)]
    assert len(pings) >= 2 + 2  # the two live ones, then played back
    assert pings[0] != pings[1]
    assert set(pings[2:]) == set(pings[:2])  # byte for byte the packets stored


def test_file_reports():
    (d,) = _data(23, 4)
    r = Reader(d)
    assert (r.text(), r.text(), r.take("I"), r.take("I"), r.take("B")) == (
        "SAT:/data",
        "a.bin",
        3000,
        0,
        0,
    )
    r.done()
    (d,) = _data(23, 8)
    r = Reader(d)
    assert (r.text(), r.text()) == ("SAT:/", "*.bin")
    assert [r.text() for _ in range(r.take("H"))] == ["SAT:/big.bin", "SAT:/data/a.bin"]
    r.done()
    (d,) = _data(23, 13)
    r = Reader(d)
    assert r.text() == "SAT:/data"
    assert [(r.take("B"), r.text()) for _ in range(r.take("H"))] == [(0, "a.bin"), (0, "new.txt")]
    r.done()
    statuses = set()
    for d in _data(23, 23):
        r = Reader(d)
        for _ in range(r.take("B")):
            op, status, done, size = r.take("H"), r.take("B"), r.take("I"), r.take("I")
            assert op == 3 and done <= size
            statuses.add(status)
        r.done()
    assert 3 in statuses


def test_failure_reports_name_the_path_code():
    loop = loops()[1]
    fails = [t for t in loop.tm if (t.service, t.subtype) == (1, 4)]
    assert fails and fails[-1].data[4] == 14


def test_our_tcs_decode_in_spacepackets():
    n = 0
    for lp in loops():
        for raw in lp.tc:
            sp = SpTc.unpack(raw)
            assert sp.apid == APID
            assert sp.source_id == 7
            assert sp.service in (2, 4, 6, 13, 14, 15, 17, 23)
            n += 1
    assert n > 40


def test_tcs_built_by_spacepackets_are_served():
    loop = Loop()
    app = loop.app
    app.register(MemoryManagement({1: BytesMemory(16, 0, True)}))
    data = struct.pack(">HBIH", 1, 1, 2, 3) + b"xyz" + struct.pack(">H", crc16_ccitt(b"xyz"))
    tc = SpTc(service=6, message_subtype=2, apid=APID, seq_count=5, app_data=data)
    asyncio.run(asyncio.sleep(0))
    app.receive(tc.pack())
    assert (loop.down[-1][7], loop.down[-1][8]) == (1, 7)
    assert bytes(app.services[6].areas[1].buf[2:5]) == b"xyz"
