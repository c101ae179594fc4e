"""Interop with spacepackets (PyPI) as an oracle: space packets, PUS-C TCs and TMs, both ways."""

import struct

import pytest
import spacepackets.ccsds.spacepacket as sp_ccsds
import spacepackets.ecss.tc as sp_tc
import spacepackets.ecss.tm as sp_tm
from hypothesis import given
from hypothesis import strategies as st
from obsw import spp  # noqa: E402
from obsw.pus.config import PusConfig  # noqa: E402
from obsw.pus.tc import PusTc  # noqa: E402
from obsw.pus.tm import PusTm  # noqa: E402

apids = st.integers(0, 0x7FF)
counts = st.integers(0, 0x3FFF)
seq_flags = st.integers(0, 3)
u8 = st.integers(0, 255)
u16 = st.integers(0, 0xFFFF)
data = st.binary(max_size=100)
NO_PEC = PusConfig(pec=False)


@given(
    st.integers(0, 1), apids, counts, seq_flags, st.booleans(), st.binary(min_size=1, max_size=80)
)
def test_space_packet_ours_to_theirs(ptype, apid, count, flags, sec, payload):
    raw = spp.SpacePacket(ptype, apid, payload, sec, flags, count).pack()
    h = sp_ccsds.SpacePacketHeader.unpack(raw)
    assert (int(h.packet_type), h.apid, h.seq_count, int(h.seq_flags)) == (
        ptype,
        apid,
        count,
        flags,
    )
    assert (h.sec_header_flag, h.data_len, h.ccsds_version) == (sec, len(payload) - 1, 0)


@given(
    st.integers(0, 1), apids, counts, seq_flags, st.booleans(), st.binary(min_size=1, max_size=80)
)
def test_space_packet_theirs_to_ours(ptype, apid, count, flags, sec, payload):
    h = sp_ccsds.SpacePacketHeader(
        sp_ccsds.PacketType(ptype),
        apid,
        count,
        len(payload) - 1,
        sec,
        sp_ccsds.SequenceFlags(flags),
    )
    raw = bytes(h.pack()) + payload
    p = spp.SpacePacket.unpack(raw)
    assert (p.packet_type, p.apid, p.seq_count, p.seq_flags) == (ptype, apid, count, flags)
    assert (bool(p.sec_header_flag), p.data) == (sec, payload)


@given(apids, u8, u8, data, counts, st.integers(0, 15), u16, seq_flags, st.booleans())
def test_tc_ours_to_theirs(apid, svc, sub, app, count, ack, src, flags, pec):
    config = PusConfig() if pec else NO_PEC
    raw = PusTc(apid, svc, sub, app, count, ack, src, flags, config).pack()
    theirs = sp_tc.PusTc.unpack(raw) if pec else sp_tc.PusTc.unpack_no_checksum(raw)
    assert (theirs.apid, theirs.service, theirs.message_subtype) == (apid, svc, sub)
    assert (theirs.seq_count, int(theirs.sp_header.seq_flags)) == (count, flags)
    assert theirs.pus_tc_sec_header.ack_flags == ack
    assert theirs.source_id == src
    assert bytes(theirs.app_data) == app
    assert theirs.pus_tc_sec_header.pus_version == 2


@given(apids, u8, u8, data, counts, st.integers(0, 15), u16, seq_flags, st.booleans())
def test_tc_theirs_to_ours(apid, svc, sub, app, count, ack, src, flags, pec):
    theirs = sp_tc.PusTc(
        service=svc,
        message_subtype=sub,
        apid=apid,
        app_data=app,
        seq_count=count,
        source_id=src,
        ack_flags=ack,
        has_checksum=pec,
    )
    theirs.sp_header.seq_flags = sp_ccsds.SequenceFlags(flags)
    tc = PusTc.unpack(bytes(theirs.pack()), PusConfig() if pec else NO_PEC)
    assert (tc.apid, tc.service, tc.subtype, tc.data) == (apid, svc, sub, app)
    assert (tc.seq_count, tc.seq_flags, tc.ack, tc.source_id) == (count, flags, ack, src)


times = st.tuples(st.integers(0, 0xFFFFFFFF), u16)


@given(apids, u8, u8, data, counts, u16, u16, times, st.integers(0, 15), seq_flags)
def test_tm_ours_to_theirs(apid, svc, sub, src, count, counter, dest, t, ref, flags):
    raw = PusTm(apid, svc, sub, src, count, counter, dest, t, ref, flags).pack()
    theirs = sp_tm.PusTm.unpack(raw, timestamp_len=6)
    assert (theirs.apid, theirs.service, theirs.message_subtype) == (apid, svc, sub)
    assert (theirs.seq_count, int(theirs.seq_flags)) == (count, flags)
    sec = theirs.pus_tm_sec_header
    assert (sec.message_counter, sec.dest_id, sec.spacecraft_time_ref) == (counter, dest, ref)
    assert bytes(theirs.timestamp) == struct.pack(">IH", *t)
    assert bytes(theirs.source_data) == src


@given(apids, u8, u8, data, counts, u16, u16, times, st.integers(0, 15), seq_flags)
def test_tm_theirs_to_ours(apid, svc, sub, src, count, counter, dest, t, ref, flags):
    theirs = sp_tm.PusTm(
        service=svc,
        message_subtype=sub,
        timestamp=struct.pack(">IH", *t),
        source_data=src,
        apid=apid,
        seq_count=count,
        message_counter=counter,
        destination_id=dest,
        misc_params=sp_tm.MiscParams(spacecraft_time_ref=ref),
    )
    theirs.seq_flags = sp_ccsds.SequenceFlags(flags)
    tm = PusTm.unpack(bytes(theirs.pack()))
    assert (tm.apid, tm.service, tm.subtype, tm.data) == (apid, svc, sub, src)
    assert (tm.seq_count, tm.seq_flags, tm.message_counter) == (count, flags, counter)
    assert (tm.destination_id, tm.time, tm.time_ref) == (dest, t, ref)


@given(st.binary(min_size=13, max_size=40))
def test_both_reject_what_fails_the_pec(body):
    # any buffer our TC decoder refuses for its CRC, spacepackets refuses too
    from obsw.pus.packets import PusCrcError, PusError

    try:
        PusTc.unpack(body)
    except PusCrcError:
        with pytest.raises((sp_tc.InvalidTcCrc16Error, ValueError)):
            sp_tc.PusTc.unpack(body)
    except PusError:
        pass
