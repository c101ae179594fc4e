"""TM transfer frames against spacepackets' TmTransferFrame, in both directions."""

import spacepackets  # noqa: F401
from obsw.crc import crc16_ccitt  # noqa: E402
from obsw.frames.clcw import Clcw  # noqa: E402
from obsw.frames.tm import TmFrame  # noqa: E402
from obsw.frames.tm_mux import TmMultiplexer, TmVirtualChannel  # noqa: E402
from spacepackets.ccsds.tm_frame import (  # noqa: E402
    MasterChannelId,
    TmFramePrimaryHeader,
    TmTransferFrame,
    TransferFrameDataFieldStatus,
    TransferFrameSecondaryHeader,
)


def test_our_frames_decode_in_spacepackets():
    vc = TmVirtualChannel(3)
    mux = TmMultiplexer(0x1AB, 120, [vc], lambda: Clcw(1, 77, retransmit=True).pack())
    vc.push(bytes((0x08, 0x10, 0xC0, 0, 0, 150)) + bytes(151))
    for k in range(2):  # a 157-byte packet in 108-byte data fields
        f = mux.frame(True)
        raw = f.pack()
        theirs = TmTransferFrame.unpack(raw, len(raw), True)
        h = theirs.primary_header
        assert h.master_channel_id.spacecraft_id == 0x1AB
        assert h.master_channel_id.transfer_frame_version == 0
        assert (h.vc_id, h.ocf_flag, h.master_ch_frame_count, h.vc_frame_count) == (3, True, k, k)
        assert h.frame_datafield_status.first_header_pointer == f.fhp
        assert h.frame_datafield_status.segment_len_id == 3
        assert theirs.data_field == f.data
        assert theirs.op_ctrl_field == Clcw(1, 77, retransmit=True).pack()
    assert mux.frame(True) is None


def test_spacepackets_frames_decode_here():
    status = TransferFrameDataFieldStatus(True, False, True, 3, 0x7FE)
    header = TmFramePrimaryHeader(MasterChannelId(0, 0x2C3), 5, True, 200, 17, status)
    sh = TransferFrameSecondaryHeader(0, 3, b"\x01\x02\x03")
    body = b"idle" * 10
    unsigned = header.pack() + sh.pack() + body + b"\x00\x04\x08\x05"
    raw = unsigned + crc16_ccitt(unsigned).to_bytes(2, "big")
    theirs = TmTransferFrame(len(raw), header, sh, body, b"\x00\x04\x08\x05", raw[-2:])
    assert theirs.pack() == raw
    f = TmFrame.unpack(raw)
    assert (f.scid, f.vcid, f.mc_count, f.vc_count, f.fhp) == (0x2C3, 5, 200, 17, 0x7FE)
    assert (f.secondary_header, f.data, f.packet_order) == (b"\x01\x02\x03", body, True)
    assert Clcw.unpack(f.ocf).report == 5
