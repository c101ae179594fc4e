"""ST[03] diagnostics and appends against puslib, both ways, byte for byte where the layouts
agree: our service user's TCs served by puslib's housekeeping service and by ours, side by
side, their TM compared; TCs puslib builds served by ours, our TM read by puslib's types.

puslib's structure reports (TM[3,10], TM[3,12]) leave out the periodic generation action
status that ours carry after the SID; the rest of those reports is compared field for field.
"""

import struct
import sys
from pathlib import Path

from puslib import packet as pl_packet
from puslib.ident import PusIdent
from puslib.parameter import Real32Parameter, UInt8Parameter, UInt16Parameter
from puslib.services import RequestVerification
from puslib.services.pus_003_housekeeping import Housekeeping as PuslibHousekeeping
from puslib.streams.buffer import QueuedOutput
from puslib.time import CucTime
from spacepackets.ecss.pus_3_hk import MessageSubtype

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "core"))

from obsw.pus import messages as M  # noqa: E402
from obsw.pus.parameters import ParameterPool  # noqa: E402
from obsw.pus.services.s03_housekeeping import Housekeeping, HousekeepingUser  # noqa: E402
from pus_loop import APID, Loop, sdb  # noqa: E402

VALUES = {1: 12.5, 2: 3.0, 3: 2}


class Both:
    """Our provider and puslib's, each fed the very same TC bytes."""

    def __init__(self):
        db = sdb()
        self.loop = Loop()
        pool = ParameterPool(db)
        pool.values.update(VALUES)
        self.ours = self.loop.app.register(Housekeeping(pool))
        self.user = self.loop.ground.register(HousekeepingUser(lambda pid: db.parameter(pid).type))
        ident = PusIdent(APID)
        self.out = QueuedOutput()
        params = {
            1: Real32Parameter(VALUES[1]),
            2: Real32Parameter(VALUES[2]),
            3: UInt8Parameter(VALUES[3]),
        }
        self.theirs = PuslibHousekeeping(
            ident, RequestVerification(ident, self.out), self.out, params
        )

    def send(self, tx):
        """Deliver the TC ``tx`` sent to both; returns (our TM data, their TM data) of
        service 3, in order."""
        raw = self.loop.up[-1]
        n = len(self.loop.tm)
        self.loop.pump()
        self.theirs.enqueue(pl_packet.PusTcPacket.deserialize(raw))
        self.theirs.process()
        theirs = []
        while not self.out.empty():
            tm = self.out.get()
            if tm.service == 3:
                theirs.append((tm.subservice, bytes(tm.source_data)))
        ours = [(t.subtype, t.data) for t in self.loop.tm[n:] if t.service == 3]
        assert tx.ok, tx.failure
        return ours, theirs


def test_our_diagnostic_requests_served_by_puslib_and_by_us_alike():
    b = Both()
    u = b.user
    b.send(u.create(APID, 5, 2, [1, 2], "diag"))
    b.send(u.append(APID, 5, [3], "diag"))
    ours, theirs = b.send(u.report_structures(APID, [5], "diag"))
    assert [s for s, _ in ours] == [s for s, _ in theirs] == [12]
    (_, mine), (_, peer) = ours[0], theirs[0]
    assert mine[:2] + mine[3:] == peer  # the same but our generation status octet
    assert mine[2] == 0  # disabled
    b.send(u.modify_interval(APID, {5: 4}, "diag"))
    b.send(u.enable(APID, [5], "diag"))
    ours, theirs = b.send(u.report_properties(APID, [5], "diag"))
    assert ours == theirs == [(36, b"\x00\x01\x00\x05\x01\x00\x04")]
    ours, theirs = b.send(u.one_shot(APID, [5], "diag"))
    expected = struct.pack(">HffB", 5, VALUES[1], VALUES[2], VALUES[3])
    assert ours == theirs == [(26, expected)]
    b.send(u.disable(APID, [5], "diag"))
    b.send(u.delete(APID, [5], "diag"))
    assert b.ours.diagnostics == {} and b.theirs._diagnostic_reports == {}


def test_housekeeping_append_alike():
    b = Both()
    u = b.user
    b.send(u.create(APID, 9, 3, [3]))
    b.send(u.append(APID, 9, [1, 2]))
    ours, theirs = b.send(u.one_shot(APID, [9]))
    assert ours == theirs == [(25, struct.pack(">HBff", 9, VALUES[3], VALUES[1], VALUES[2]))]


def _puslib_tc(subtype, data, seq):
    return pl_packet.PusTcPacket.create(
        apid=APID,
        name=seq,
        pus_version=2,
        ack_flags=pl_packet.AckFlag(0b1111),
        service_type=3,
        service_subtype=subtype,
        source=7,
        data=data,
    ).serialize()


def _u16(*values):
    return b"".join(bytes(UInt16Parameter(v)) for v in values)


def test_tcs_puslib_builds_are_served_by_us_and_our_tm_reads_in_puslib():
    b = Both()
    app = b.loop.app
    # create diagnostic structure 6 (interval 2, parameters 1 and 3, no groups), append 2
    for seq, (subtype, data) in enumerate(
        (
            (2, _u16(6, 2, 2, 1, 3, 0)),
            (30, _u16(6, 1, 2, 0)),
            (7, _u16(1, 6)),
            (28, _u16(1, 6)),
            (34, _u16(1, 6)),
        )
    ):
        app.receive(_puslib_tc(subtype, data, seq))
    b.loop.pump()
    reports = {}
    for raw, t in zip(b.loop.raw, b.loop.tm):
        tm = pl_packet.PusTmPacket.deserialize(
            raw, cuc_time=CucTime(0, 0, 4, 2, has_preamble=False)
        )
        assert (tm.service, tm.subservice) == (t.service, t.subtype)
        reports.setdefault(tm.subservice, []).append(bytes(tm.source_data or b""))
    assert app.counters["completed"] == 5
    (diag,) = reports[26]
    assert UInt16Parameter.from_bytes(diag[:2]) == 6
    assert Real32Parameter.from_bytes(diag[2:6]) == VALUES[1]
    assert UInt8Parameter.from_bytes(diag[6:7]) == VALUES[3]
    assert Real32Parameter.from_bytes(diag[7:11]) == VALUES[2]
    (props,) = reports[36]
    assert props == _u16(1, 6) + b"\x01" + _u16(2)


def test_subtypes_agree_with_spacepackets():
    for ours, theirs in (
        (M.TC_HK_ENABLE_DIAG_REPORTS, MessageSubtype.TC_ENABLE_PERIODIC_DIAGNOSTICS_GEN),
        (M.TC_HK_DISABLE_DIAG_REPORTS, MessageSubtype.TC_DISABLE_PERIODIC_DIAGNOSTICS_GEN),
        (M.TC_HK_REPORT_DIAG_STRUCTURES, MessageSubtype.TM_REPORT_DIAG_REPORT_STRUCTURES),
        (M.TM_HK_DIAG_STRUCTURE_REPORT, MessageSubtype.TM_DIAG_DEFINITION_REPORT),
        (M.TM_HK_DIAG_REPORT, MessageSubtype.TM_DIAGNOSTICS_REPORT),
        (M.TC_HK_ONE_SHOT_DIAG, MessageSubtype.TC_GENERATE_ONE_DIAGNOSTICS_REPORT),
        (
            M.TC_HK_MODIFY_DIAG_INTERVAL,
            MessageSubtype.TC_MODIFY_DIAGNOSTICS_REPORT_COLLECTION_INTERVAL,
        ),
    ):
        assert ours == (3, int(theirs))
