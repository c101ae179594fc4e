"""Functional monitoring (ST[12] 17-28), parameter definitions (ST[20] 4-7) and ranges against
the peers: every TM decoded by spacepackets and puslib field for field, every TC our users send
parsed by both with the same application data, and TCs built by spacepackets (application data
packed here from the standard's field layout) served by us byte for byte like our own."""

import asyncio
import json
import struct
import sys
from pathlib import Path

from puslib.packet import PusTcPacket as PuslibTc
from puslib.packet import PusTmPacket as PuslibTm
from puslib.time import CucTime
from spacepackets.ecss.tc import PusTc as SpTc
from spacepackets.ecss.tm import PusTm as SpTm

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "core"))

from obsw.pus.events import EventManager  # noqa: E402
from obsw.pus.parameters import ParameterPool  # noqa: E402
from obsw.pus.sdb import Sdb  # noqa: E402
from obsw.pus.services.s01_verification import FAILURE_OUT_OF_RANGE  # noqa: E402
from obsw.pus.services.s05_events import EventReporting  # noqa: E402
from obsw.pus.services.s06_memory import BytesMemory  # noqa: E402
from obsw.pus.services.s12_functional import FunctionalOnBoardMonitoring  # noqa: E402
from obsw.pus.services.s12_functional_user import (  # noqa: E402
    FunctionalMonitoringUser,
    functional_check,
)
from obsw.pus.services.s12_user import limit_check  # noqa: E402
from obsw.pus.services.s20_parameters import ParameterManagement, ParameterUser  # noqa: E402
from pus_loop import APID, SDB, Loop  # noqa: E402


def database():
    doc = json.loads(SDB)
    doc["memories"] = [{"id": 1, "name": "ram", "start": 4096, "size": 64, "writable": True}]
    doc["components"][0]["attributes"].append(
        {
            "name": "heater",
            "parameter": 6,
            "type": "uint16",
            "unit": "degC",
            "writable": True,
            "calibration": {"polynomial": [-50, 0.05]},
            "range": [-10, 40],
        }
    )
    return Sdb(doc)


def scenario():
    db = database()
    loop = Loop()
    pool = ParameterPool(db)
    pool.values.update({1: 20.0, 2: 3.0, 3: 2, 4: True, 6: 1400})
    app, ground = loop.app, loop.ground
    app.register(EventReporting(known=db.events))
    app.register(FunctionalOnBoardMonitoring(pool, db.events))
    app.register(ParameterManagement(pool, {1: BytesMemory(64, start=4096)}))
    EventManager(db).connect(app)
    types = lambda pid: db.parameter(pid).type  # noqa: E731
    ids = lambda k: db.parameter(k).id  # noqa: E731
    s12 = ground.register(FunctionalMonitoringUser(types, ids))
    s20 = ground.register(
        ParameterUser(types, lambda pid: db.parameter(pid).qualified, ids, db.parameter)
    )

    async def main():
        for tx in (
            s12.add(APID, [limit_check(1, 1, -10.0, 45.0), limit_check(2, 2, 0.0, 5.0)]),
            s12.enable(APID, [1, 2]),
            s12.add_functional(APID, [functional_check(7, [1, 2], 1, 4, "Panel.deployed", 1, 1)]),
            s12.enable_functional(APID, [7]),
            s12.protect_functional(APID, [7]),
            s12.report_functional(APID, [7]),
            s12.report_functional_status(APID),
            s12.unprotect_functional(APID, [7]),
            s12.disable_functional(APID, [7]),
            s12.disable_functional_function(APID),
            s12.enable_functional_function(APID),
            s12.enable_functional(APID, [7]),
            s20.change_raw_definitions(APID, [("Panel.speed", 1, 4100)]),
            s20.change_object_definitions(APID, [("Panel.mode", 1, 0, 8)]),
            s20.report_definitions(APID, [2, 3, 6]),
            s20.set(APID, {"Panel.heater": 30.0}),
        ):
            loop.pump()
            await app.idle()
            loop.pump()
            assert tx.ok, tx.failure
        pool.values[1] = 90.0
        loop.clock.advance(1.0)
        app.tick()
        loop.pump()
        s12.report_functional_status(APID)
        s12.disable_functional(APID, [7])
        s12.delete_functional(APID, [7])
        loop.pump()

    asyncio.run(main())
    return loop, pool


LOOP, POOL = scenario()


def tm_of(service, subtype):
    return [
        raw for raw, t in zip(LOOP.raw, LOOP.tm) if (t.service, t.subtype) == (service, subtype)
    ]


def sp(raw):
    return SpTm.unpack(raw, timestamp_len=6).source_data


def pl(raw):
    return PuslibTm.deserialize(raw, cuc_time=CucTime(0, 0, 4, 2, has_preamble=False)).source_data


def test_every_new_type_was_exchanged():
    tcs = {(t.service, t.message_subtype) for t in (SpTc.unpack(raw) for raw in LOOP.tc)}
    assert {(12, s) for s in (17, 18, 19, 20, 21, 22, 23, 24, 25, 27)} <= tcs
    assert {(20, 4), (20, 5), (20, 6)} <= tcs
    tms = {(t.service, t.subtype) for t in LOOP.tm}
    assert {(12, 26), (12, 28), (20, 7)} <= tms


def test_our_tcs_parse_in_both_peers_with_the_standard_layout():
    layouts = {
        (12, 17): b"",
        (12, 18): b"",
        (12, 19): struct.pack(">HH", 1, 7),
        (12, 21): struct.pack(">HH", 1, 7),
        (12, 23): struct.pack(">HHHIIHHHH", 1, 7, 4, 1, 1, 4, 1, 2, 1) + struct.pack(">H", 2),
        (12, 25): struct.pack(">HH", 1, 7),
        (12, 27): b"",
        (20, 4): struct.pack(">BHHI", 1, 2, 1, 4100),
        (20, 5): struct.pack(">BHHHI", 1, 3, 1, 0, 8),
        (20, 6): struct.pack(">BHHH", 3, 2, 3, 6),
        (20, 3): struct.pack(">BHH", 1, 6, 1600),  # 30 degC sent raw
    }
    seen = set()
    for raw in LOOP.tc:
        tc = SpTc.unpack(raw)
        key = (tc.service, tc.message_subtype)
        assert (PuslibTc.deserialize(raw).app_data or b"") == tc.app_data
        if key in layouts and key not in seen:
            assert tc.app_data == layouts[key], key
            seen.add(key)
    assert seen == set(layouts)


def test_functional_reports_decode_field_for_field():
    (report,) = tm_of(12, 26)
    assert sp(report) == pl(report)
    n, fmon, vpid, mask, value, prot, en, event, failing, n2 = struct.unpack_from(
        ">HHHIIBBHHH", sp(report)
    )
    assert (n, fmon, vpid, mask, value, prot, en, event, failing, n2) == (
        1, 7, 4, 1, 1, 1, 1, 4, 1, 2,
    )  # fmt: skip
    assert struct.unpack_from(">HH", sp(report), 22) == (1, 2) and len(sp(report)) == 26
    first, last = tm_of(12, 28)
    assert sp(first) == struct.pack(">HHBBB", 1, 7, 1, 1, 0)  # protected, enabled, unchecked
    assert sp(last) == struct.pack(">HHBBB", 1, 7, 0, 1, 3)  # failed
    event = [raw for raw, t in zip(LOOP.raw, LOOP.tm) if (t.service, t.subtype) == (5, 3)]
    assert sp(event[0]) == struct.pack(">HH", 4, 7)  # event 4, FMON 7


def test_definition_report_decodes_field_for_field():
    (report,) = tm_of(20, 7)
    assert sp(report) == pl(report)
    assert sp(report) == struct.pack(
        ">B" + "HBHHI" * 3, 3, 2, 1, 1, 0, 4100, 3, 2, 1, 0, 8, 6, 0, 0, 0, 0
    )
    assert POOL.get(6) == 1600


def test_spacepackets_tcs_served_like_ours():
    db = database()
    loop = Loop()
    pool = ParameterPool(db)
    pool.values.update({1: 20.0, 2: 3.0, 3: 2, 4: True, 6: 1400})
    ram = BytesMemory(64, start=4096)
    loop.app.register(EventReporting(known=db.events))
    mon = loop.app.register(FunctionalOnBoardMonitoring(pool, db.events))
    loop.app.register(ParameterManagement(pool, {1: ram}))
    add = struct.pack(">HHHHIIHHB", 1, 1, 1, 0, 0, 0, 1, 1, 1) + struct.pack(
        ">fHfH", -10, 0, 45, 0
    )
    fmon = struct.pack(">HHHIIHHH", 1, 9, 0, 0, 0, 3, 1, 1) + struct.pack(">H", 1)
    n = 20
    for service, subtype, data in (
        (12, 5, add),
        (12, 1, struct.pack(">HH", 1, 1)),
        (12, 23, fmon),
        (12, 19, struct.pack(">HH", 1, 9)),
        (12, 21, struct.pack(">HH", 1, 9)),
        (20, 4, struct.pack(">BHHI", 1, 2, 1, 4096)),
        (20, 3, struct.pack(">BHfHH", 2, 2, 1.5, 6, 2000)),  # 50 degC: out of range
    ):
        tc = SpTc(apid=APID, service=service, message_subtype=subtype, app_data=data, seq_count=n)
        n += 1
        asyncio.run(_serve(loop, tc.pack()))
    f = mon.fmons[9]
    assert (f.enabled, f.protected, f.d["pmons"], f.d["event"]) == (True, True, [1], 3)
    assert ram.read(0, 4) == b"\x00\x00\x00\x00"  # the refused set changed nothing
    assert pool.get(6) == 1400
    failures = [t for t in loop.tm if (t.service, t.subtype) == (1, 4)]
    assert len(failures) == 1
    rid, code, pid = struct.unpack(">4sBH", failures[0].data)
    assert (code, pid) == (FAILURE_OUT_OF_RANGE, 6)


async def _serve(loop, raw):
    loop.app.receive(raw)
    for _ in range(5):
        loop.pump()
        await loop.app.idle()
    loop.pump()
