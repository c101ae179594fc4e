"""Every TM our service providers emit, decoded by spacepackets and puslib field for field;
every TC our service users send, decoded by both; TCs built by spacepackets served by us."""

import asyncio
import struct
import sys
from pathlib import Path

from puslib.packet import PusTcPacket as PuslibTc
from puslib.packet import PusTmPacket as PuslibTm
from puslib.parameter import (
    BoolParameter,
    Real32Parameter,
    UInt8Parameter,
    UInt16Parameter,
    UInt32Parameter,
)
from puslib.time import CucTime
from spacepackets.ecss.pus_1_verification import ManagedParamsVerification, Service1Tm
from spacepackets.ecss.pus_17_test import Service17Tm
from spacepackets.ecss.tc import PusTc as SpTc
from spacepackets.ecss.tm import ManagedParams
from spacepackets.ecss.tm import PusTm as SpTm

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "core"))

from obsw.pus.events import EventManager  # noqa: E402
from obsw.pus.packets import ACK_ALL, ACK_PROGRESS  # noqa: E402
from obsw.pus.parameters import ParameterPool  # noqa: E402
from obsw.pus.services.base import Service  # noqa: E402
from obsw.pus.services.s01_verification import FAILURE_REFUSED, PusFailure  # noqa: E402
from obsw.pus.services.s03_housekeeping import Housekeeping, HousekeepingUser  # noqa: E402
from obsw.pus.services.s05_events import EventReporting, EventUser  # noqa: E402
from obsw.pus.services.s09_time import TimeManagement, TimeUser  # noqa: E402
from obsw.pus.services.s17_test import ServiceTest, ServiceTestUser  # noqa: E402
from obsw.pus.services.s20_parameters import ParameterManagement, ParameterUser  # noqa: E402
from pus_loop import APID, Loop, sdb  # noqa: E402


class Steps(Service):
    """Progress steps and failures at each later stage, for reports no standard TC causes."""

    SERVICE = 200
    HANDLERS = (((200, 1), "run"),)

    def run(self, req):
        req.progress(1)
        if req.data == b"\x01":
            raise PusFailure(FAILURE_REFUSED, data=b"\x07", step=2)
        if req.data == b"\x02":
            raise PusFailure(FAILURE_REFUSED, data=b"\x08\x09")


def scenario():
    """Run every subtype of every service once; return the loop with all TM and TC."""
    db = sdb()
    loop = Loop()
    loop.clock.advance(2_100_000_000)  # a realistic TAI time for the TM time field
    pool = ParameterPool(db)
    pool.values.update({1: 12.5, 2: 3.0, 3: 2})
    app, ground = loop.app, loop.ground
    app.register(Housekeeping(pool, db.housekeeping))
    app.register(EventReporting(known=db.events))
    app.register(TimeManagement())
    app.register(ServiceTest())
    app.register(ParameterManagement(pool))
    app.register(Steps())
    events = EventManager(db)
    events.connect(app)
    types = lambda pid: db.parameter(pid).type  # noqa: E731
    names = lambda pid: db.parameter(pid).qualified  # noqa: E731
    hk = ground.register(HousekeepingUser(types, names, db.housekeeping))
    ev = ground.register(EventUser(db.event))
    tm = ground.register(TimeUser())
    t17 = ground.register(ServiceTestUser())
    s20 = ground.register(ParameterUser(types, names, lambda k: db.parameter(k).id))

    async def main():
        for _tx in (
            t17.ping(APID),
            t17.connection_test(APID, APID),
            t17.connection_test(APID, 99),  # start failure
            hk.create(APID, 5, 2, [1, 4, 100]),
            hk.report_structures(APID, [1, 5]),
            hk.one_shot(APID, [1]),
            hk.enable(APID, [5]),
            hk.modify_interval(APID, {5: 1}),
            hk.report_properties(APID, [1, 5]),
            hk.disable(APID, [5]),
            hk.delete(APID, [5]),
            ev.disable(APID, [3]),
            ev.report_disabled(APID),
            ev.enable(APID, [3]),
            tm.set_rate(APID, 0),
            s20.report(APID, ["Panel.angle", "Panel.speed", "Panel.mode"]),
            s20.set(APID, {"Panel.speed": 4.5}),
        ):
            loop.pump()
            await app.idle()
            loop.pump()
        ground.send(APID, 17, 1, b"", None, ACK_ALL | ACK_PROGRESS)
        ground.send(APID, 17, 9)  # acceptance failure
        for data in (b"", b"\x01", b"\x02"):
            ground.send(APID, 200, 1, data, None, ACK_ALL | ACK_PROGRESS)
        loop.pump()
        hk.enable(APID, [1])
        loop.pump()
        for _severity, name in (
            (1, "Panel.moved"),
            (2, "low_one"),
            (3, "medium_one"),
            (4, "Panel.stuck"),
        ):
            events.raise_event(name, 1)
        for _ in range(2):
            loop.clock.advance(1.0)
            app.tick()
        loop.pump()

    asyncio.run(main())
    return loop


LOOP = None


def all_tm():
    global LOOP
    if LOOP is None:
        LOOP = scenario()
    return list(zip(LOOP.raw, LOOP.tm))


def test_scenario_covers_every_tm_type():
    kinds = {(t.service, t.subtype) for _, t in all_tm()}
    expected = {
        (1, 1),
        (1, 2),
        (1, 3),
        (1, 4),
        (1, 5),
        (1, 6),
        (1, 7),
        (1, 8),
        (3, 10),
        (3, 25),
        (3, 35),
        (5, 1),
        (5, 2),
        (5, 3),
        (5, 4),
        (5, 8),
        (9, 2),
        (17, 2),
        (17, 4),
        (20, 2),
    }
    assert expected <= kinds, expected - kinds


def test_every_tm_header_decodes_in_both_peers():
    tms = all_tm()
    assert len(tms) > 80
    for raw, ours in tms:
        _check_header(raw, ours)


def _check_header(raw, ours):
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
    pl = PuslibTm.deserialize(raw, cuc_time=CucTime(0, 0, 4, 2, has_preamble=False))
    assert pl.header.apid == ours.apid
    assert pl.header.seq_count_or_name == ours.seq_count
    assert (pl.service, pl.subservice) == (ours.service, ours.subtype)
    assert (pl.source_data or b"") == ours.data


def _by_type(service, subtype):
    return [(raw, t) for raw, t in all_tm() if (t.service, t.subtype) == (service, subtype)]


def test_verification_reports_in_spacepackets():
    params = ManagedParams(timestamp_len=6)
    verif = ManagedParamsVerification(bytes_step_id=1, bytes_err_code=1)
    n = 0
    for raw, ours in all_tm():
        if ours.service != 1:
            continue
        tm = Service1Tm.unpack(raw, params, verif)
        rid = tm.tc_req_id
        assert rid.tc_packet_id.apid == APID
        assert rid.tc_psc.seq_count == struct.unpack(">H", ours.data[2:4])[0] & 0x3FFF
        if ours.subtype in (5, 6):
            assert tm.step_id.val == ours.data[4]
        if ours.subtype % 2 == 0:
            code_at = 5 if ours.subtype == 6 else 4
            assert tm.error_code.val == ours.data[code_at]
            assert tm.failure_notice.data == ours.data[code_at + 1 :]
        n += 1
    assert n > 40


def test_service_17_in_spacepackets():
    for raw, ours in _by_type(17, 2) + _by_type(17, 4):
        tm = Service17Tm.unpack(raw, timestamp_len=6)
        assert tm.message_subtype == ours.subtype
        if ours.subtype == 4:
            assert UInt16Parameter.from_bytes(tm.source_data) == APID


def _puslib_data(raw):
    return PuslibTm.deserialize(raw, cuc_time=CucTime(0, 0, 4, 2, has_preamble=False)).source_data


def test_housekeeping_fields_in_puslib():
    reports = _by_type(3, 25)
    assert reports
    for raw, _ours in reports:
        data = _puslib_data(raw)
        sid = UInt16Parameter.from_bytes(data)
        if sid == 1:
            assert Real32Parameter.from_bytes(data[2:6]) == 12.5
            assert Real32Parameter.from_bytes(data[6:10]) in (3.0, 4.5)  # before, after the set
            assert UInt8Parameter.from_bytes(data[10:11]) == 2
            assert len(data) == 11
    structures = [_puslib_data(raw) for raw, _ in _by_type(3, 10)]
    five = [d for d in structures if UInt16Parameter.from_bytes(d) == 5][0]
    # SID, generation status, interval, N1, parameter IDs, NFA
    assert UInt8Parameter.from_bytes(five[2:3]) == 0
    assert UInt16Parameter.from_bytes(five[3:5]) == 2
    assert UInt16Parameter.from_bytes(five[5:7]) == 3
    assert [UInt16Parameter.from_bytes(five[i : i + 2]) for i in (7, 9, 11)] == [1, 4, 100]
    assert UInt16Parameter.from_bytes(five[13:15]) == 0
    props = _puslib_data(_by_type(3, 35)[0][0])
    assert UInt16Parameter.from_bytes(props) == 2  # N
    assert [
        UInt16Parameter.from_bytes(props[2:4]),
        UInt8Parameter.from_bytes(props[4:5]),
        UInt16Parameter.from_bytes(props[5:7]),
    ] == [1, 0, 2]
    assert [
        UInt16Parameter.from_bytes(props[7:9]),
        UInt8Parameter.from_bytes(props[9:10]),
        UInt16Parameter.from_bytes(props[10:12]),
    ] == [5, 1, 1]


def test_event_fields_in_puslib():
    for severity, event_id in ((1, 1), (2, 3), (3, 4), (4, 2)):
        ((raw, ours),) = _by_type(5, severity)
        data = _puslib_data(raw)
        assert UInt16Parameter.from_bytes(data) == event_id
    data = _puslib_data(_by_type(5, 1)[0][0])
    assert Real32Parameter.from_bytes(data[2:]) == 1.0
    disabled = _puslib_data(_by_type(5, 8)[0][0])
    assert UInt8Parameter.from_bytes(disabled) == 1
    assert UInt16Parameter.from_bytes(disabled[1:]) == 3


def test_time_report_fields_in_puslib():
    raw, ours = _by_type(9, 2)[0]
    data = _puslib_data(raw)
    assert UInt8Parameter.from_bytes(data) == 0
    assert UInt32Parameter.from_bytes(data[1:5]) == ours.time[0]
    assert UInt16Parameter.from_bytes(data[5:7]) == ours.time[1]
    assert UInt8Parameter.from_bytes(data[7:8]) == 0


def test_parameter_report_fields_in_puslib():
    raw, ours = _by_type(20, 2)[0]
    data = _puslib_data(raw)
    assert UInt8Parameter.from_bytes(data) == 3
    assert UInt16Parameter.from_bytes(data[1:3]) == 1
    assert Real32Parameter.from_bytes(data[3:7]) == 12.5
    assert UInt16Parameter.from_bytes(data[7:9]) == 2
    assert Real32Parameter.from_bytes(data[9:13]) == 3.0
    assert UInt16Parameter.from_bytes(data[13:15]) == 3
    assert UInt8Parameter.from_bytes(data[15:16]) == 2
    assert BoolParameter.from_bytes(b"\x01") is True


def test_our_tcs_decode_in_both_peers():
    all_tm()
    assert len(LOOP.tc) > 15
    for raw in LOOP.tc:
        sp = SpTc.unpack(raw)
        pl = PuslibTc.deserialize(raw)
        assert sp.apid == pl.header.apid == APID
        assert (sp.service, sp.message_subtype) == (pl.service, pl.subservice)
        assert sp.source_id == pl.secondary_header.source == 7
        assert sp.app_data == (pl.app_data or b"")


def test_spacepackets_tcs_are_served():
    loop = Loop()
    loop.app.register(ServiceTest())
    for seq in range(3):
        tc = SpTc(apid=APID, service=17, message_subtype=1, seq_count=seq, source_id=3)
        loop.app.receive(tc.pack())
    tc = SpTc(
        apid=APID, service=17, message_subtype=3, app_data=struct.pack(">H", APID), seq_count=3
    )
    loop.app.receive(tc.pack())
    loop.pump()
    assert [t.subtype for t in loop.tm if t.service == 17] == [2, 2, 2, 4]
    assert loop.app.counters["completed"] == 4
