"""ST[09] CDS time reports against spacepackets, both ways: a rate set by a spacepackets TC,
our TM[9,3] read by spacepackets (packet and CDS short time code), and a CDS time field
spacepackets packs decoded by our service user."""

import sys
from pathlib import Path

from spacepackets.ccsds.time import CdsShortTimestamp
from spacepackets.ecss.tc import PusTc as SpTc
from spacepackets.ecss.tm import PusTm as SpTm

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "core"))

from obsw.pus.services.s09_time import CDS_TIME_REPORT, TimeManagement, TimeUser  # noqa: E402
from obsw.pus.tm import PusTm  # noqa: E402
from pus_loop import APID, Loop  # noqa: E402

DAY = 86400


def test_spacepackets_sets_the_rate_and_reads_our_cds_reports():
    loop = Loop()
    loop.clock.advance(DAY * 24000 + 2723.25)  # from 1000 s: day 24000 after 1958, 01:02:03.25
    loop.app.register(TimeManagement(code="cds"))
    loop.app.receive(SpTc(apid=APID, service=9, message_subtype=1, app_data=bytes([2])).pack())
    for _ in range(9):
        loop.clock.advance(1.0)
        loop.app.tick()
    loop.pump()
    reports = [raw for raw, t in zip(loop.raw, loop.tm) if (t.service, t.subtype) == (9, 3)]
    assert len(reports) == 3  # every 4 s over 9 s, the first at once
    for i, raw in enumerate(reports):
        tm = SpTm.unpack(raw, timestamp_len=6)
        assert (tm.service, tm.message_subtype) == (9, 3)
        data = tm.source_data
        assert data[0] == 2 and data[-1] == 0  # exponent, time reference status
        cds = CdsShortTimestamp.unpack(bytes([CdsShortTimestamp.CDS_SHORT_ID << 4]) + data[1:7])
        assert cds.ccsds_days == 24000
        assert cds.ms_of_day == 3724250 + 4000 * i  # the first report one cycle after the TC
        assert cds.pack()[1:] == data[1:7]


def test_our_user_reads_a_cds_field_spacepackets_packs():
    cds = CdsShortTimestamp(ccsds_days=21000, ms_of_day=86399999)
    data = bytes([5]) + cds.pack()[1:] + bytes([1])
    raw = PusTm(APID, 9, 3, data, 0, 0, 0, (0, 0)).pack()
    user = TimeUser()
    out = user.decode_cds_time(PusTm.unpack(raw))
    assert out["exponent"] == 5 and out["status"] == 1
    assert abs(out["time"] - (21000 * DAY + 86399.999)) < 1e-6
    assert CDS_TIME_REPORT.pack({"exponent": 5, "time": (21000, 86399999), "status": 1}) == data
