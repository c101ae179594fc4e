"""Interop with puslib (PyPI) as an oracle: PUS-C TCs and TMs in several layouts, both ways."""

import puslib.packet as pl_packet
import puslib.time as pl_time
from hypothesis import given
from hypothesis import strategies as st
from obsw.pus.config import PusConfig  # noqa: E402
from obsw.pus.tc import PusTc  # noqa: E402
from obsw.pus.tm import PusTm  # noqa: E402
from obsw.timecode import Cuc  # noqa: E402

apids = st.integers(0, 0x7FF)
counts = st.integers(0, 0x3FFF)
seq_flags = st.integers(0, 3)
u8 = st.integers(0, 255)
u16 = st.integers(0, 0xFFFF)
data = st.binary(max_size=100)

# (has source/counter/destination fields, PEC, explicit CUC P-field) for each layout tried
layouts = st.tuples(st.booleans(), st.booleans(), st.booleans())


def _config(fields, pec, explicit):
    n = 2 if fields else 0
    return PusConfig(
        source_id_size=n,
        destination_id_size=n,
        message_counter_size=n,
        time=Cuc(4, 2, explicit=explicit),
        pec=pec,
    )


def _cuc(t, explicit):
    return pl_time.CucTime(t[0], t[1], 4, 2, has_preamble=explicit)


@given(apids, u8, u8, data, counts, st.integers(0, 15), u16, seq_flags, layouts)
def test_tc_ours_to_theirs(apid, svc, sub, app, count, ack, src, flags, layout):
    fields, pec, _ = layout
    raw = PusTc(apid, svc, sub, app, count, ack, src if fields else 0, flags, _config(*layout))
    theirs = pl_packet.PusTcPacket.deserialize(raw.pack(), has_pec=pec, has_source_field=fields)
    assert (theirs.apid, theirs.service, theirs.subservice) == (apid, svc, sub)
    assert (theirs.name, int(theirs.header.seq_flags)) == (count, flags)
    assert int(theirs.secondary_header.ack_flags) == ack
    assert theirs.secondary_header.pus_version == 2
    assert theirs.source == (src if fields else None)
    assert (theirs.app_data or b"") == app


@given(apids, u8, u8, data, counts, st.integers(0, 15), u16, seq_flags, layouts)
def test_tc_theirs_to_ours(apid, svc, sub, app, count, ack, src, flags, layout):
    fields, pec, _ = layout
    theirs = pl_packet.PusTcPacket.create(
        apid=apid,
        name=count,
        seq_flags=flags,
        pus_version=2,
        ack_flags=pl_packet.AckFlag(ack),
        service_type=svc,
        service_subtype=sub,
        source=src if fields else None,
        data=app,
        has_pec=pec,
    )
    tc = PusTc.unpack(theirs.serialize(), _config(*layout))
    assert (tc.apid, tc.service, tc.subtype, tc.data) == (apid, svc, sub, app)
    assert (tc.seq_count, tc.seq_flags, tc.ack) == (count, flags, ack)
    assert tc.source_id == (src if fields else 0)


times = st.tuples(st.integers(0, 0xFFFFFFFF), u16)


@given(apids, u8, u8, data, counts, u16, u16, times, st.integers(0, 15), seq_flags, layouts)
def test_tm_ours_to_theirs(apid, svc, sub, src, count, counter, dest, t, ref, flags, layout):
    fields, pec, explicit = layout
    if not fields:
        counter = dest = 0
    raw = PusTm(apid, svc, sub, src, count, counter, dest, t, ref, flags, _config(*layout))
    theirs = pl_packet.PusTmPacket.deserialize(
        raw.pack(),
        has_pec=pec,
        cuc_time=None if explicit else _cuc((0, 0), False),
        has_type_counter_field=fields,
        has_destination_field=fields,
    )
    assert (theirs.apid, theirs.service, theirs.subservice) == (apid, svc, sub)
    assert (theirs.seq_count, int(theirs.header.seq_flags)) == (count, flags)
    assert theirs.secondary_header.spacecraft_time_ref_status == ref
    assert theirs.counter == (counter if fields else None)
    assert theirs.destination == (dest if fields else None)
    assert theirs.time.time_field == t
    assert (theirs.source_data or b"") == src


@given(apids, u8, u8, data, counts, u16, u16, times, st.integers(0, 15), seq_flags, layouts)
def test_tm_theirs_to_ours(apid, svc, sub, src, count, counter, dest, t, ref, flags, layout):
    fields, pec, explicit = layout
    theirs = pl_packet.PusTmPacket.create(
        apid=apid,
        seq_count=count,
        seq_flags=flags,
        pus_version=2,
        spacecraft_time_ref_status=ref,
        service_type=svc,
        service_subtype=sub,
        msg_type_counter=counter if fields else None,
        destination=dest if fields else None,
        time=_cuc(t, explicit),
        data=src,
        has_pec=pec,
    )
    tm = PusTm.unpack(theirs.serialize(), _config(*layout))
    assert (tm.apid, tm.service, tm.subtype, tm.data) == (apid, svc, sub, src)
    assert (tm.seq_count, tm.seq_flags, tm.time, tm.time_ref) == (count, flags, t, ref)
    assert (tm.message_counter, tm.destination_id) == ((counter, dest) if fields else (0, 0))
