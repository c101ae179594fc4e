"""Services 8, 11, 12, 19, 21 and 22: every TM they emit decoded by spacepackets field for
field; every TC their users send decoded by spacepackets; spacepackets-built TCs (with
spacepackets-built TCs inside) scheduled, sequenced and acted on by us."""

import asyncio
import json
import struct
import sys
from pathlib import Path

from spacepackets.ecss.tc import PusTc as SpTc
from spacepackets.ecss.tm import PusTm as SpTm

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "core"))

from obsw.pus.events import EventManager  # noqa: E402
from obsw.pus.parameters import ParameterPool  # noqa: E402
from obsw.pus.sdb import Sdb  # noqa: E402
from obsw.pus.services.s05_events import EventReporting  # noqa: E402
from obsw.pus.services.s08_functions import FunctionManagement, FunctionUser, functions  # noqa: E402
from obsw.pus.services.s11_scheduling import TimeScheduling, TimeSchedulingUser  # noqa: E402
from obsw.pus.services.s12_monitoring import OnBoardMonitoring  # noqa: E402
from obsw.pus.services.s12_user import OnBoardMonitoringUser, delta_check, limit_check  # noqa: E402
from obsw.pus.services.s17_test import ServiceTest  # noqa: E402
from obsw.pus.services.s19_event_action import EventAction, EventActionUser  # noqa: E402
from obsw.pus.services.s21_sequencing import RequestSequencing, RequestSequencingUser  # noqa: E402
from obsw.pus.services.s22_position_scheduling import (  # noqa: E402
    PositionScheduling,
    PositionSchedulingUser,
)
from pus_loop import APID, SDB, Loop  # noqa: E402

T0 = 2_100_000_000.0


def scenario():
    doc = json.loads(SDB)
    doc["functions"] = [{"id": 7, "name": "local.noop"}]
    db = Sdb(doc)
    loop = Loop()
    loop.clock.advance(T0 - loop.clock.now())
    pool = ParameterPool(db)
    pool.values.update({1: 20.0, 2: 3.0, 3: 2, 100: 0})
    app, ground = loop.app, loop.ground
    app.register(EventReporting(known=db.events))
    app.register(ServiceTest())
    table = functions(db)
    app.register(FunctionManagement(table, local={7: lambda: None}))
    app.register(TimeScheduling(subschedules=2))
    app.register(PositionScheduling(pool, "count"))
    app.register(OnBoardMonitoring(pool, db.events))
    app.register(EventAction(known=db.events))
    app.register(RequestSequencing())
    EventManager(db).connect(app)
    types = lambda pid: db.parameter(pid).type  # noqa: E731
    s8 = ground.register(FunctionUser(table))
    s11 = ground.register(TimeSchedulingUser())
    s22 = ground.register(PositionSchedulingUser())
    s12 = ground.register(OnBoardMonitoringUser(types, lambda k: db.parameter(k).id))
    s19 = ground.register(EventActionUser())
    s21 = ground.register(RequestSequencingUser())

    def tick(n=1, dt=1.0):
        for _ in range(n):
            loop.clock.advance(dt)
            app.tick()
        loop.pump()

    async def main():
        ping = [s11.embed(APID, 17, 1)[0] for _ in range(4)]
        perform = s11.embed(APID, 8, 1, s8.pack(7))[0]
        for _tx in (
            s8.perform(APID, 7),
            s11.create_groups(APID, [3]),
            s11.insert(APID, [(T0 + 5, ping[0], 1, 3), (T0 + 6.5, perform)]),
            s11.detail_all(APID),
            s11.summary_filter(APID, T0, T0 + 10),
            s11.subschedule_status(APID),
            s11.group_status(APID),
            s11.shift_all(APID, 0.25),
            s22.insert(APID, [(40, ping[1])]),
            s22.detail(APID, [(7, APID, 1)]),
            s22.summary_all(APID),
            s22.subschedule_status(APID),
            s22.create_groups(APID, [2]),
            s22.group_status(APID),
            s12.add(
                APID,
                [
                    limit_check(1, "Panel.angle", -10.0, 45.0, high_event=4),
                    delta_check(2, "count", -1.0, 1.0, high_event=3),
                ],
            ),
            s12.enable(APID, [1, 2]),
            s12.report_definitions(APID),
            s12.report_status(APID),
            s19.add(APID, [(APID, 4, ping[2])]),
            s19.enable(APID, [(APID, 4)]),
            s19.report_status(APID),
            s19.report_definitions(APID),
            s21.load(APID, "seq", [(ping[3], 1.0)]),
            s21.report_content(APID, "seq"),
            s21.checksum(APID, "seq"),
            s21.report_status(APID),
            s21.activate(APID, "seq"),
        ):
            loop.pump()
            await app.idle()
            loop.pump()
        tick()
        pool.values[1] = 50.0  # out of limits: TM[12,12], event 4, the action runs
        pool.values[100] = 45  # the rover moves past the ST[22] activity; delta too high
        tick(2)
        s12.report_out_of_limits(APID)
        s21.abort_all(APID)
        loop.pump()
        tick(8)

    asyncio.run(main())
    return loop


LOOP = None


def all_tm():
    global LOOP
    if LOOP is None:
        LOOP = scenario()
    return list(zip(LOOP.raw, LOOP.tm))


def by_type(service, subtype):
    return [(raw, t) for raw, t in all_tm() if (t.service, t.subtype) == (service, subtype)]


def sp(raw):
    return SpTm.unpack(raw, timestamp_len=6)


def test_scenario_covers_every_report_type():
    kinds = {(t.service, t.subtype) for _, t in all_tm()}
    expected = {
        (11, 10),
        (11, 13),
        (11, 19),
        (11, 27),
        (12, 9),
        (12, 11),
        (12, 12),
        (12, 14),
        (19, 7),
        (19, 11),
        (21, 7),
        (21, 10),
        (21, 12),
        (21, 14),
        (22, 10),
        (22, 13),
        (22, 19),
        (22, 27),
        (17, 2),
    }
    assert expected <= kinds, expected - kinds
    failures = [t for _, t in all_tm() if t.service == 1 and t.subtype % 2 == 0]
    assert failures == []
    assert len(by_type(17, 2)) == 4  # scheduled, position-scheduled, action, sequence
    assert len(by_type(5, 3)) == 1


def test_every_tm_decodes_in_spacepackets_field_for_field():
    tms = all_tm()
    assert len(tms) > 100
    for raw, ours in tms:
        tm = sp(raw)
        assert (tm.apid, tm.seq_count, tm.service, tm.message_subtype) == (
            ours.apid,
            ours.seq_count,
            ours.service,
            ours.subtype,
        )
        sec = tm.pus_tm_sec_header
        assert sec.message_counter == ours.message_counter
        assert sec.dest_id == ours.destination_id
        assert sec.timestamp == struct.pack(">IH", *ours.time)
        assert tm.source_data == ours.data
        assert tm.pack() == raw


def _inner(data, at):
    """The TC packet at ``at`` in ``data``, decoded by spacepackets, and where it ends."""
    size = struct.unpack_from(">H", data, at + 4)[0] + 7
    return SpTc.unpack(data[at : at + size]), at + size


def test_time_schedule_reports_in_spacepackets():
    detail = sp(by_type(11, 10)[0][0]).source_data
    assert struct.unpack_from(">H", detail) == (2,)
    sub, group, coarse, fine = struct.unpack_from(">BBIH", detail, 2)
    assert (sub, group, coarse, fine) == (1, 3, int(T0) + 5, 0)
    tc, end = _inner(detail, 10)
    assert (tc.service, tc.message_subtype, tc.source_id, tc.apid) == (17, 1, 7, APID)
    sub, group, coarse, fine = struct.unpack_from(">BBIH", detail, end)
    assert (sub, group, coarse, fine) == (0, 0, int(T0) + 6, 32768)
    tc, end = _inner(detail, end + 8)
    assert (tc.service, tc.message_subtype, tc.app_data) == (8, 1, b"\x00\x07\x00")
    assert end == len(detail)
    summary = sp(by_type(11, 13)[0][0]).source_data
    assert struct.unpack(">HBBIHHHH", summary[:16]) == (2, 1, 3, int(T0) + 5, 0, 7, APID, 0)
    subs = sp(by_type(11, 19)[0][0]).source_data
    assert subs == bytes([2, 0, 1, 1, 1])
    groups = sp(by_type(11, 27)[0][0]).source_data
    assert groups == bytes([1, 3, 1])


def test_position_schedule_reports_in_spacepackets():
    detail = sp(by_type(22, 10)[0][0]).source_data
    assert struct.unpack_from(">HBBI", detail) == (1, 0, 0, 40)
    tc, end = _inner(detail, 8)
    assert (tc.service, tc.message_subtype, tc.seq_count) == (17, 1, 1)
    assert end == len(detail)
    summary = sp(by_type(22, 13)[0][0]).source_data
    assert struct.unpack(">HBBIHHH", summary) == (1, 0, 0, 40, 7, APID, 1)
    assert sp(by_type(22, 19)[0][0]).source_data == bytes([1, 0, 1])
    assert sp(by_type(22, 27)[0][0]).source_data == bytes([1, 2, 1])


def test_monitoring_reports_in_spacepackets():
    defs = sp(by_type(12, 9)[0][0]).source_data
    delay, n = struct.unpack_from(">HH", defs)
    assert (delay, n) == (0, 2)
    head = struct.unpack_from(">HHHIIHBHB", defs, 4)
    assert head == (1, 1, 0, 0, 0, 1, 1, 1, 1)  # PMON 1: angle, enabled, limit check
    assert struct.unpack_from(">fHfH", defs, 24) == (-10.0, 0, 45.0, 4)
    head = struct.unpack_from(">HHHIIHBHB", defs, 36)
    assert head == (2, 100, 0, 0, 0, 1, 1, 1, 2)  # PMON 2: count, delta check
    assert struct.unpack_from(">dHdHH", defs, 56) == (-1.0, 0, 1.0, 3, 1)
    assert len(defs) == 56 + 22
    status = sp(by_type(12, 14)[0][0]).source_data
    assert status == struct.pack(">HHBHB", 2, 1, 1, 2, 1)
    transitions = [sp(raw).source_data for raw, _ in by_type(12, 12)]
    found = []
    for data in transitions:
        (n,) = struct.unpack_from(">H", data)
        at = 2
        for _ in range(n):
            pmon, pid, check = struct.unpack_from(">HHB", data, at)
            fmt = ">ffBBIH" if check == 1 else ">ddBBIH"
            value, limit, prev, cur, coarse, fine = struct.unpack_from(fmt, data, at + 5)
            found.append((pmon, pid, check, value, limit, prev, cur))
            at += 5 + struct.calcsize(fmt)
        assert at == len(data)
    assert (1, 1, 1, 50.0, 45.0, 2, 4) in found
    assert (2, 100, 2, 45.0, 1.0, 0, 4) in found
    out = sp(by_type(12, 11)[0][0]).source_data
    assert struct.unpack_from(">HHHB", out) == (1, 1, 1, 1)  # only PMON 1 is still out


def test_event_action_reports_in_spacepackets():
    assert sp(by_type(19, 7)[0][0]).source_data == struct.pack(">BHHB", 1, APID, 4, 1)
    data = sp(by_type(19, 11)[0][0]).source_data
    assert struct.unpack_from(">BHHB", data) == (1, APID, 4, 1)
    tc, end = _inner(data, 6)
    assert (tc.service, tc.message_subtype, tc.seq_count) == (17, 1, 2)
    assert end == len(data)
    event = sp(by_type(5, 3)[0][0]).source_data
    assert event == struct.pack(">HHH", 4, 1, 1)  # event 4, PMON 1, parameter 1


def test_sequencing_reports_in_spacepackets():
    content = sp(by_type(21, 12)[0][0]).source_data
    assert content[:4] == b"\x03seq"
    assert struct.unpack_from(">H", content, 4) == (1,)
    tc, end = _inner(content, 6)
    assert (tc.service, tc.message_subtype, tc.seq_count) == (17, 1, 3)
    assert struct.unpack_from(">iH", content, end) == (1, 0)
    checksum = sp(by_type(21, 10)[0][0]).source_data
    assert checksum[:4] == b"\x03seq" and len(checksum) == 6
    assert sp(by_type(21, 7)[0][0]).source_data == b"\x00\x01\x03seq\x00"
    assert sp(by_type(21, 14)[0][0]).source_data == b"\x00\x00"  # ended before the abort


def test_our_tcs_decode_in_spacepackets():
    all_tm()
    services = set()
    for raw in LOOP.tc:
        tc = SpTc.unpack(raw)
        assert tc.apid == APID and tc.source_id == 7
        assert tc.pack() == raw
        services.add(tc.service)
    assert {8, 11, 12, 19, 21, 22} <= services


def test_spacepackets_tcs_scheduled_sequenced_and_acted_on():
    doc = json.loads(SDB)
    db = Sdb(doc)
    loop = Loop()
    app = loop.app
    app.register(EventReporting(known=db.events))
    app.register(ServiceTest())
    app.register(TimeScheduling())
    app.register(EventAction(known=db.events))
    app.register(RequestSequencing())
    events = EventManager(db)
    events.connect(app)
    ping = [
        SpTc(apid=APID, service=17, message_subtype=1, seq_count=i, source_id=5) for i in range(3)
    ]
    t = int(loop.clock.now()) + 3
    insert = struct.pack(">HBBIH", 1, 0, 0, t, 0) + ping[0].pack()
    add = struct.pack(">BHH", 1, APID, 3) + ping[1].pack()
    load = b"\x01s" + struct.pack(">H", 1) + ping[2].pack() + struct.pack(">iH", 0, 0)
    n = 10
    for service, subtype, data in (
        (11, 4, insert),
        (19, 1, add),
        (19, 4, struct.pack(">BHH", 1, APID, 3)),
        (21, 1, load),
        (21, 4, b"\x01s"),
    ):
        tc = SpTc(apid=APID, service=service, message_subtype=subtype, app_data=data, seq_count=n)
        n += 1
        app.receive(tc.pack())
    events.raise_event("low_one")
    for _ in range(4):
        loop.clock.advance(1.0)
        app.tick()
    loop.pump()
    pings = [tm for tm in loop.tm if (tm.service, tm.subtype) == (17, 2)]
    assert len(pings) == 3
    assert all(tm.destination_id == 5 for tm in pings)
    failures = [tm for tm in loop.tm if tm.service == 1 and tm.subtype % 2 == 0]
    assert failures == []
