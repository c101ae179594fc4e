"""Property tests of the CFDP core: PDU and TLV round trips, random bytes raise only the
declared decode errors, class 2 completes under random loss patterns."""

import os
import sys

from hypothesis import given, settings
from hypothesis import strategies as st

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "core"))

from cfdp_sim import Link, make_pair  # noqa: E402
from obsw.cfdp import msgs  # noqa: E402
from obsw.cfdp.defs import FILE_DATA, CfdpError  # noqa: E402
from obsw.cfdp.pdu import decode_pdu  # noqa: E402
from obsw.cfdp.pdu.ack import AckPdu  # noqa: E402
from obsw.cfdp.pdu.eof import EofPdu  # noqa: E402
from obsw.cfdp.pdu.filedata import FileDataPdu  # noqa: E402
from obsw.cfdp.pdu.finished import FinishedPdu  # noqa: E402
from obsw.cfdp.pdu.header import PduHeader  # noqa: E402
from obsw.cfdp.pdu.keepalive import KeepAlivePdu  # noqa: E402
from obsw.cfdp.pdu.metadata import MetadataPdu  # noqa: E402
from obsw.cfdp.pdu.nak import NakPdu  # noqa: E402
from obsw.cfdp.pdu.prompt import PromptPdu  # noqa: E402
from obsw.cfdp.tlv import (  # noqa: E402
    FaultHandlerOverride,
    FilestoreRequest,
    FilestoreResponse,
    FlowLabel,
    MessageToUser,
    unpack_tlvs,
)

SETTINGS = settings(max_examples=200, deadline=None)
u8 = st.integers(0, 255)
names = st.text(min_size=1, max_size=40).filter(lambda s: len(s.encode()) <= 255)


@st.composite
def headers(draw):
    eid_len = draw(st.integers(1, 8))
    seq_len = draw(st.integers(1, 8))
    return PduHeader(
        draw(st.integers(0, (1 << (8 * eid_len)) - 1)),
        draw(st.integers(0, (1 << (8 * eid_len)) - 1)),
        draw(st.integers(0, (1 << (8 * seq_len)) - 1)),
        direction=draw(st.integers(0, 1)),
        mode=draw(st.integers(0, 1)),
        crc=draw(st.booleans()),
        large=draw(st.booleans()),
        seg_ctrl=draw(st.booleans()),
        eid_len=eid_len,
        seq_len=seq_len,
    )


def fss(h):
    return st.integers(0, (1 << (64 if h.large else 32)) - 1)


tlvs = st.one_of(
    st.builds(FilestoreRequest, st.integers(0, 8), names, names),
    st.builds(
        FilestoreResponse,
        st.integers(0, 8),
        st.integers(0, 15),
        names,
        names,
        st.binary(max_size=20),
    ),
    st.builds(MessageToUser, st.binary(max_size=100)),
    st.builds(FaultHandlerOverride, st.integers(0, 15), st.integers(0, 15)),
    st.builds(FlowLabel, st.binary(max_size=10)),
)


def _normalize(t):
    # a request or response whose action has one name drops the second one on the wire
    if isinstance(t, (FilestoreRequest, FilestoreResponse)) and t.action not in (2, 3, 4):
        t.second = None
    return t


@st.composite
def pdus(draw):
    h = draw(headers())
    kind = draw(st.integers(0, 7))
    if kind == 0:
        seg_meta = draw(st.booleans())
        h = h.copy(pdu_type=FILE_DATA, seg_meta=seg_meta)
        return FileDataPdu(
            h,
            draw(fss(h)),
            draw(st.binary(max_size=200)),
            draw(st.integers(0, 3)) if seg_meta else 0,
            draw(st.binary(max_size=63)) if seg_meta else b"",
        )
    if kind == 1:
        opts = [_normalize(t) for t in draw(st.lists(tlvs, max_size=4))]
        return MetadataPdu(
            h,
            draw(fss(h)),
            draw(st.none() | names),
            draw(st.none() | names),
            draw(st.integers(0, 15)),
            draw(st.booleans()),
            opts,
        )
    if kind == 2:
        cond = draw(st.integers(0, 15))
        return EofPdu(
            h,
            cond,
            draw(st.integers(0, 2**32 - 1)),
            draw(fss(h)),
            draw(st.integers(0, (1 << (8 * h.eid_len)) - 1)) if cond else None,
        )
    if kind == 3:
        resp = [
            _normalize(FilestoreResponse(a, s, n, n))
            for a, s, n in draw(
                st.lists(st.tuples(st.integers(0, 8), st.integers(0, 15), names), max_size=3)
            )
        ]
        return FinishedPdu(
            h,
            draw(st.integers(0, 15)),
            draw(st.integers(0, 1)),
            draw(st.integers(0, 3)),
            resp,
            draw(st.none() | st.integers(0, (1 << (8 * h.eid_len)) - 1)),
        )
    if kind == 4:
        return AckPdu(
            h, draw(st.sampled_from([4, 5])), draw(st.integers(0, 15)), draw(st.integers(0, 3))
        )
    if kind == 5:
        segs = draw(st.lists(st.tuples(fss(h), fss(h)), max_size=10))
        return NakPdu(h, draw(fss(h)), draw(fss(h)), segs)
    if kind == 6:
        return PromptPdu(h, draw(st.integers(0, 1)))
    return KeepAlivePdu(h, draw(fss(h)))


@SETTINGS
@given(pdus())
def test_pdu_round_trip(pdu):
    raw = pdu.pack()
    back = decode_pdu(raw)
    assert back == pdu
    assert back.pack() == raw


@SETTINGS
@given(st.binary(max_size=300))
def test_random_bytes_raise_only_decode_errors(raw):
    try:
        decode_pdu(raw)
    except CfdpError:
        pass


@SETTINGS
@given(pdus(), st.data())
def test_mutated_pdus_raise_only_decode_errors(pdu, data):
    raw = bytearray(pdu.pack())
    for _ in range(data.draw(st.integers(1, 4))):
        i = data.draw(st.integers(0, len(raw) - 1))
        raw[i] = data.draw(u8)
    cut = data.draw(st.integers(0, len(raw)))
    try:
        decode_pdu(bytes(raw[:cut]))
    except CfdpError:
        pass


@SETTINGS
@given(st.lists(tlvs, max_size=6))
def test_tlv_round_trip(items):
    items = [_normalize(t) for t in items]
    raw = b"".join(t.pack() for t in items)
    assert unpack_tlvs(raw) == items


@SETTINGS
@given(st.binary(max_size=60))
def test_reserved_message_random_bytes(raw):
    try:
        msgs.parse(MessageToUser(b"cfdp" + raw))
    except CfdpError:
        pass


@settings(max_examples=40, deadline=None)
@given(
    st.integers(0, 3000),
    st.integers(1, 10**6),
    st.floats(0.0, 0.4),
    st.floats(0.0, 0.2),
    st.floats(0.0, 0.3),
    st.booleans(),
)
def test_class2_completes_under_random_loss(size, seed, loss, dup, reorder, immediate):
    data = bytes((i * 31 + seed) & 0xFF for i in range(size))
    a, b = make_pair(
        files_a={"f": data}, mode=0, immediate_nak=immediate, ack_limit=20, nak_limit=20
    )
    a.put(2, "f", "g")
    link = Link(a, b, seed=seed, loss=loss, dup=dup, reorder=reorder)
    assert link.run(max_time=10**6)
    assert bytes(b.fs.files["g"]) == data
    assert [i.info["condition"] for i in link.finished(0)] == [0]
    assert [i.info["condition"] for i in link.finished(1)] == [0]
