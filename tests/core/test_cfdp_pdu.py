"""CFDP PDU codecs: vectors worked out by hand from 727.0-B-5 field definitions, round trips,
and malformed input."""

import unittest
from binascii import unhexlify

from obsw.cfdp.defs import (
    ACKNOWLEDGED,
    DIR_EOF,
    DIR_FINISHED,
    FILE_DATA,
    TOWARD_SENDER,
    UNACKNOWLEDGED,
    CfdpError,
    PduCrcError,
    PduFormatError,
    PduTooShortError,
)
from obsw.cfdp.pdu import decode_pdu
from obsw.cfdp.pdu.ack import AckPdu
from obsw.cfdp.pdu.eof import EofPdu
from obsw.cfdp.pdu.filedata import FileDataPdu
from obsw.cfdp.pdu.finished import FinishedPdu
from obsw.cfdp.pdu.header import PduHeader
from obsw.cfdp.pdu.keepalive import KeepAlivePdu
from obsw.cfdp.pdu.metadata import MetadataPdu
from obsw.cfdp.pdu.nak import NakPdu
from obsw.cfdp.pdu.prompt import PromptPdu
from obsw.cfdp.tlv import FilestoreResponse, MessageToUser
from obsw.crc import crc16_ccitt


def h(hexstr):
    return unhexlify(hexstr.replace(" ", ""))


def hdr(**kw):
    return PduHeader(1, 2, 7, **kw)


class TestVectors(unittest.TestCase):
    # header of every vector: version 001, then flags; data length; lengths octet; 01 07 02
    def test_eof_class2(self):
        pdu = EofPdu(hdr(mode=ACKNOWLEDGED), 0, 0xDEADBEEF, 100)
        want = h("20 000a 00 01 07 02  04 00 deadbeef 00000064")
        self.assertEqual(pdu.pack(), want)
        self.assertEqual(decode_pdu(want), pdu)

    def test_eof_cancel_with_fault_location(self):
        pdu = EofPdu(hdr(mode=ACKNOWLEDGED), 15, 0x01020304, 5, 1)
        want = h("20 000d 00 01 07 02  04 f0 01020304 00000005 06 01 01")
        self.assertEqual(pdu.pack(), want)
        back = decode_pdu(want)
        self.assertEqual(back.condition, 15)
        self.assertEqual(back.fault_location, 1)

    def test_metadata_class1_closure_crc32(self):
        pdu = MetadataPdu(hdr(mode=UNACKNOWLEDGED), 16, "a", "b", 3, True)
        want = h("24 000a 00 01 07 02  07 43 00000010 01 61 01 62")
        self.assertEqual(pdu.pack(), want)
        back = decode_pdu(want)
        self.assertEqual((back.source_name, back.dest_name), ("a", "b"))
        self.assertTrue(back.closure)
        self.assertEqual(back.checksum_type, 3)

    def test_metadata_with_message_option(self):
        pdu = MetadataPdu(hdr(), 0, None, None, 15, False, [MessageToUser(b"hi")])
        want = h("24 000c 00 01 07 02  07 0f 00000000 00 00 02 02 6869")
        self.assertEqual(pdu.pack(), want)
        back = decode_pdu(want)
        self.assertIsNone(back.source_name)
        self.assertEqual(back.messages_to_user, [MessageToUser(b"hi")])

    def test_file_data_large_with_segment_metadata(self):
        header = PduHeader(0x0102, 3, 9, pdu_type=FILE_DATA, large=True, seg_meta=True, eid_len=2)
        pdu = FileDataPdu(header, 1 << 32, b"Z", 1, b"xy")
        want = h("35 000c 18 0102 09 0003  42 7879 0000000100000000 5a")
        self.assertEqual(pdu.pack(), want)
        back = decode_pdu(want)
        self.assertEqual((back.offset, back.data, back.rcs), (1 << 32, b"Z", 1))
        self.assertEqual(back.segment_metadata, b"xy")

    def test_file_data_plain(self):
        pdu = FileDataPdu(hdr(pdu_type=FILE_DATA, mode=ACKNOWLEDGED), 0x10, b"abc")
        self.assertEqual(pdu.pack(), h("30 0007 00 01 07 02 00000010 616263"))

    def test_ack_of_finished(self):
        pdu = AckPdu(hdr(mode=ACKNOWLEDGED), DIR_FINISHED, 0, 1)
        self.assertEqual(pdu.pack(), h("20 0003 00 01 07 02 06 51 01"))

    def test_ack_of_eof_cancel(self):
        pdu = AckPdu(hdr(mode=ACKNOWLEDGED, direction=TOWARD_SENDER), DIR_EOF, 15, 1)
        want = h("28 0003 00 01 07 02 06 40 f1")
        self.assertEqual(pdu.pack(), want)
        back = decode_pdu(want)
        self.assertEqual((back.directive, back.condition, back.status), (DIR_EOF, 15, 1))

    def test_nak(self):
        pdu = NakPdu(
            hdr(mode=ACKNOWLEDGED, direction=TOWARD_SENDER), 0, 0x200, [(0, 0), (0x100, 0x180)]
        )
        want = h("28 0019 00 01 07 02 08 00000000 00000200 00000000 00000000 00000100 00000180")
        self.assertEqual(pdu.pack(), want)
        self.assertEqual(decode_pdu(want).segments, [(0, 0), (0x100, 0x180)])

    def test_finished_with_filestore_response(self):
        resp = FilestoreResponse(2, 0, "a", "b")
        pdu = FinishedPdu(hdr(mode=ACKNOWLEDGED, direction=TOWARD_SENDER), 0, 0, 2, [resp])
        want = h("28 000a 00 01 07 02 05 02 01 06 20 0161 0162 00")
        self.assertEqual(pdu.pack(), want)
        back = decode_pdu(want)
        self.assertEqual(back.responses, [resp])
        self.assertEqual(back.file_status, 2)

    def test_finished_cancelled_with_fault_location(self):
        pdu = FinishedPdu(hdr(direction=TOWARD_SENDER), 15, 1, 0, (), 2)
        want = h("2c 0005 00 01 07 02 05 f4 06 01 02")
        self.assertEqual(pdu.pack(), want)
        back = decode_pdu(want)
        self.assertEqual((back.condition, back.delivery, back.fault_location), (15, 1, 2))

    def test_prompt_keep_alive(self):
        self.assertEqual(PromptPdu(hdr(mode=0), 1).pack(), h("20 0002 00 01 07 02 09 80"))

    def test_keep_alive(self):
        pdu = KeepAlivePdu(hdr(mode=0, direction=TOWARD_SENDER), 0x400)
        self.assertEqual(pdu.pack(), h("28 0005 00 01 07 02 0c 00000400"))

    def test_crc_flag_appends_crc16(self):
        pdu = PromptPdu(hdr(mode=0, crc=True), 0)
        raw = pdu.pack()
        body = h("22 0004 00 01 07 02 09 00")
        crc = crc16_ccitt(body)
        self.assertEqual(raw, body + bytes((crc >> 8, crc & 0xFF)))
        self.assertEqual(decode_pdu(raw), pdu)

    def test_long_entity_ids(self):
        header = PduHeader(0x0102030405060708, 0x1122, 0xABCDEF)
        self.assertEqual(header.eid_len, 8)
        self.assertEqual(header.seq_len, 3)
        pdu = PromptPdu(header, 0)
        back = decode_pdu(pdu.pack())
        self.assertEqual(back.header.source, 0x0102030405060708)
        self.assertEqual(back.header.dest, 0x1122)
        self.assertEqual(back.header.seq, 0xABCDEF)


class TestErrors(unittest.TestCase):
    def test_short_header(self):
        with self.assertRaises(PduTooShortError):
            decode_pdu(b"\x20\x00")

    def test_short_data_field(self):
        raw = EofPdu(hdr(), 0, 0, 1).pack()
        with self.assertRaises(PduTooShortError):
            decode_pdu(raw[:-1])

    def test_bad_version(self):
        with self.assertRaises(PduFormatError):
            decode_pdu(h("40 0002 00 01 07 02 09 00"))

    def test_unknown_directive(self):
        with self.assertRaises(PduFormatError):
            decode_pdu(h("20 0002 00 01 07 02 0e 00"))

    def test_crc_mismatch(self):
        raw = bytearray(PromptPdu(hdr(crc=True), 0).pack())
        raw[-3] ^= 0x80
        with self.assertRaises(PduCrcError):
            decode_pdu(bytes(raw))

    def test_errors_are_value_errors(self):
        self.assertTrue(issubclass(CfdpError, ValueError))
        for bad in (b"", b"\x20\x00\x05\x00\x01\x07\x02\x07", h("20 0002 00 01 07 02 08 00")):
            with self.assertRaises(CfdpError):
                decode_pdu(bad)

    def test_nak_odd_segment_bytes(self):
        with self.assertRaises(PduFormatError):
            decode_pdu(h("28 000b 00 01 07 02 08 00000000 00000010 00 00"))

    def test_large_offset_needs_large_mode(self):
        with self.assertRaises(PduFormatError):
            FileDataPdu(hdr(pdu_type=FILE_DATA), 1 << 32, b"x").pack()


class TestRoundTrips(unittest.TestCase):
    def test_each_type_both_modes_and_flags(self):
        for large in (False, True):
            for crc in (False, True):
                base = hdr(large=large, crc=crc, mode=ACKNOWLEDGED)
                back = hdr(large=large, crc=crc, mode=ACKNOWLEDGED, direction=TOWARD_SENDER)
                pdus = [
                    MetadataPdu(base, 123456, "src/a.bin", "dst/b.bin", 2, True),
                    FileDataPdu(base.copy(pdu_type=FILE_DATA), 99, b"payload"),
                    EofPdu(base, 0, 0xFFFFFFFF, 123456),
                    FinishedPdu(back, 0, 0, 2),
                    AckPdu(back, DIR_EOF, 0, 1),
                    NakPdu(back, 0, 500, [(1, 2), (300, 400)]),
                    PromptPdu(base, 0),
                    KeepAlivePdu(back, 77),
                ]
                for p in pdus:
                    self.assertEqual(decode_pdu(p.pack()), p)
                    self.assertEqual(type(p).unpack(p.pack()), p)


if __name__ == "__main__":
    unittest.main()
