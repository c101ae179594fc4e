"""CFDP TLVs, LVs and the reserved messages to user."""

import unittest

from obsw.cfdp import msgs
from obsw.cfdp.defs import CfdpError, PduTooShortError
from obsw.cfdp.tlv import (
    EntityIdTlv,
    FaultHandlerOverride,
    FilestoreRequest,
    FilestoreResponse,
    FlowLabel,
    MessageToUser,
    Tlv,
    pack_tlvs,
    unpack_tlvs,
)


class TestTlv(unittest.TestCase):
    def test_filestore_request_vectors(self):
        # create file: action 0 in the high nibble, one LV
        self.assertEqual(FilestoreRequest(0, "f").pack(), b"\x00\x03\x00\x01f")
        # rename carries a second LV
        self.assertEqual(FilestoreRequest(2, "a", "b").pack(), b"\x00\x05\x20\x01a\x01b")

    def test_filestore_response_vector(self):
        r = FilestoreResponse(1, 1, "gone", message=b"no")
        self.assertEqual(r.pack(), b"\x01\x09\x11\x04gone\x02no")
        self.assertEqual(Tlv.unpack(r.pack()), r)

    def test_fault_handler_override_vector(self):
        self.assertEqual(FaultHandlerOverride(7, 4).pack(), b"\x04\x01\x74")

    def test_entity_id_flow_label_message(self):
        self.assertEqual(EntityIdTlv(0x1234).pack(), b"\x06\x02\x12\x34")
        self.assertEqual(FlowLabel(b"\x09").pack(), b"\x05\x01\x09")
        self.assertEqual(MessageToUser(b"x").pack(), b"\x02\x01x")

    def test_list_round_trip(self):
        tlvs = [
            FilestoreRequest(3, "a", "b"),
            FilestoreResponse(5, 0, "d"),
            MessageToUser(b"hello"),
            FaultHandlerOverride(1, 2),
            FlowLabel(b"fl"),
            EntityIdTlv(9),
            Tlv(0x33, b"unknown type kept"),
        ]
        self.assertEqual(unpack_tlvs(pack_tlvs(tlvs)), tlvs)

    def test_truncated(self):
        with self.assertRaises(PduTooShortError):
            unpack_tlvs(b"\x02\x05abc")
        with self.assertRaises(CfdpError):
            unpack_tlvs(b"\x00\x02\x20\x05")


class TestReservedMessages(unittest.TestCase):
    def test_proxy_put_request_vector(self):
        m = msgs.proxy_put_request(2, "a", "bc")
        self.assertEqual(m.value, b"cfdp\x00\x01\x02\x01a\x02bc")
        self.assertEqual(
            msgs.parse(m),
            (msgs.PROXY_PUT_REQUEST, {"dest_id": 2, "source_name": "a", "dest_name": "bc"}),
        )

    def test_originating_transaction_id_vector(self):
        m = msgs.originating_transaction_id((0x0102, 5))
        # lengths octet: entity id length-1 in bits 1-3, sequence length-1 in bits 5-7
        self.assertEqual(m.value, b"cfdp\x0a\x10\x01\x02\x05")
        self.assertEqual(msgs.parse(m)[1]["tid"], (0x0102, 5))

    def test_all_round_trip(self):
        tid = (3, 300)
        cases = [
            (msgs.proxy_message_to_user(b"m"), {"data": b"m"}),
            (msgs.proxy_filestore_request(FilestoreRequest(1, "x")), None),
            (msgs.proxy_fault_handler_override(8, 3), {"condition": 8, "handler": 3}),
            (msgs.proxy_transmission_mode(1), {"mode": 1}),
            (msgs.proxy_flow_label(b"f"), {"data": b"f"}),
            (msgs.proxy_segmentation_control(True), {"preserve": True}),
            (msgs.proxy_put_response(0, 0, 2), {"condition": 0, "delivery": 0, "file_status": 2}),
            (msgs.proxy_filestore_response(FilestoreResponse(0, 0, "y")), None),
            (msgs.proxy_put_cancel(), {}),
            (msgs.proxy_closure_request(True), {"closure": True}),
            (msgs.directory_listing_request("d", "l"), {"directory": "d", "listing_file": "l"}),
            (
                msgs.directory_listing_response(False, "d", "l"),
                {"ok": False, "directory": "d", "listing_file": "l"},
            ),
            (msgs.remote_status_report_request(tid, "r"), {"tid": tid, "report_file": "r"}),
            (
                msgs.remote_status_report_response(tid, 1, True),
                {"status": 1, "ok": True, "tid": tid},
            ),
            (msgs.remote_suspend_request(tid), {"tid": tid}),
            (
                msgs.remote_suspend_response(tid, True, 1),
                {"suspended": True, "status": 1, "tid": tid},
            ),
            (msgs.remote_resume_request(tid), {"tid": tid}),
            (
                msgs.remote_resume_response(tid, False, 1),
                {"suspended": False, "status": 1, "tid": tid},
            ),
        ]
        for m, fields in cases:
            back = MessageToUser.unpack(m.pack())
            kind, f = msgs.parse(back)
            self.assertEqual(kind, m.value[4])
            if fields is not None:
                self.assertEqual(f, fields)
        self.assertEqual(msgs.parse(cases[1][0])[1]["request"], FilestoreRequest(1, "x"))
        self.assertEqual(msgs.parse(cases[7][0])[1]["response"], FilestoreResponse(0, 0, "y"))

    def test_user_message_is_not_reserved(self):
        self.assertIsNone(msgs.parse(MessageToUser(b"hello world")))


if __name__ == "__main__":
    unittest.main()
