"""PUS-C TC and TM packets: vectors from the standard's field definitions, errors, options."""

import unittest

from obsw import spp
from obsw.pus import messages
from obsw.pus.any_packet import unpack_packet
from obsw.pus.config import DEFAULT, PusConfig
from obsw.pus.packets import (
    ACK_ACCEPTANCE,
    ACK_COMPLETION,
    PusCrcError,
    PusError,
    PusHeaderError,
    PusLengthError,
    PusVersionError,
    RequestId,
    failure_code,
)
from obsw.pus.tc import PusTc
from obsw.pus.tm import PusTm
from obsw.timecode import Cds, Cuc
from pus_sealed import crc_bitwise, sealed

# TC[17,1] to APID 0x073, count 25, all acknowledgement flags, source ID 0:
#   packet ID 0001 1000 0111 0011 (version 0, TC, secondary header, APID 0x073)
#   sequence control 11 + 14-bit 25 -> 0xC019; data length 5 + 0 + 2 - 1 = 6
#   PUS version 2 | ack 1111 -> 0x2F; service 0x11; subtype 0x01; source ID 0x0000
TC_17_1 = sealed("1873 c019 0006 2f 11 01 0000")
# TC[20,3] to APID 0x100, count 0x3FFF, ack acceptance+completion (1001), source 0xABCD, 4 octets
TC_20_3 = sealed("1900 ffff 000a 29 14 03 abcd 01020304")
# TM[3,25] from APID 0x065, count 5, time reference status 1, message type counter 7,
# destination 9, CUC 4+2 time 0x01020304.0x0506, source data AA BB:
#   data length 3 + 2 + 2 + 6 + 2 + 2 - 1 = 16
TM_3_25 = sealed("0865 c005 0010 21 03 19 0007 0009 01020304 0506 aabb")


class TestVectors(unittest.TestCase):
    def test_crc_helper_matches_catalogue(self):
        self.assertEqual(crc_bitwise(b"123456789"), 0x29B1)

    def test_tc_17_1_pack(self):
        self.assertEqual(PusTc(0x73, 17, 1, seq_count=25).pack(), TC_17_1)

    def test_tc_17_1_unpack(self):
        tc = PusTc.unpack(TC_17_1)
        self.assertEqual((tc.apid, tc.service, tc.subtype), (0x73, 17, 1))
        self.assertEqual(tc.message_type, messages.TC_TEST_ARE_YOU_ALIVE)
        self.assertEqual(tc.seq_count, 25)
        self.assertEqual(tc.seq_flags, spp.SEQ_UNSEGMENTED)
        self.assertEqual(tc.ack, 15)
        self.assertEqual(tc.source_id, 0)
        self.assertEqual(tc.data, b"")
        self.assertEqual(tc.packet_id, 0x1873)
        self.assertEqual(tc.sequence_control, 0xC019)

    def test_tc_20_3(self):
        tc = PusTc(
            0x100, 20, 3, b"\x01\x02\x03\x04", 0x3FFF, ACK_ACCEPTANCE | ACK_COMPLETION, 0xABCD
        )
        self.assertEqual(tc.pack(), TC_20_3)
        back = PusTc.unpack(TC_20_3)
        self.assertEqual(back, tc)
        self.assertEqual(back.ack, 9)
        self.assertEqual(back.source_id, 0xABCD)
        self.assertEqual(back.data, b"\x01\x02\x03\x04")

    def test_tm_3_25(self):
        tm = PusTm(0x65, 3, 25, b"\xaa\xbb", 5, 7, 9, (0x01020304, 0x0506), time_ref=1)
        self.assertEqual(tm.pack(), TM_3_25)
        back = PusTm.unpack(TM_3_25)
        self.assertEqual(back, tm)
        self.assertEqual(back.time, (0x01020304, 0x0506))
        self.assertEqual(back.time_ref, 1)
        self.assertEqual(back.message_counter, 7)
        self.assertEqual(back.destination_id, 9)
        self.assertEqual(back.message_type, messages.TM_HK_HK_REPORT)

    def test_pec_residue_is_zero(self):
        # appending the CRC makes the CRC over the whole packet zero (ECSS-E-ST-70-41C annex B)
        for raw in (TC_17_1, TC_20_3, TM_3_25):
            self.assertEqual(crc_bitwise(raw), 0)

    def test_unpack_packet_picks_by_type_bit(self):
        self.assertIsInstance(unpack_packet(TC_17_1), PusTc)
        self.assertIsInstance(unpack_packet(TM_3_25), PusTm)

    def test_unpack_from_walks_a_buffer(self):
        buf = b"\x00" + TC_17_1 + TC_20_3
        a, end = PusTc.unpack_from(buf, 1)
        b, end2 = PusTc.unpack_from(buf, end)
        self.assertEqual((a.service, b.service, end2), (17, 20, len(buf)))

    def test_mutable_buffers(self):
        self.assertEqual(PusTc.unpack(bytearray(TC_20_3)).data, b"\x01\x02\x03\x04")
        self.assertIsInstance(PusTm.unpack(bytearray(TM_3_25)).data, bytes)
        self.assertEqual(PusTc.unpack(memoryview(TC_17_1)).seq_count, 25)


class TestRequestId(unittest.TestCase):
    def test_request_id_of_tc(self):
        r = PusTc.unpack(TC_20_3).request_id()
        self.assertEqual(r.pack(), bytes.fromhex("1900ffff"))
        self.assertEqual((r.version, r.packet_type, r.sec_header_flag), (0, 1, 1))
        self.assertEqual((r.apid, r.seq_flags, r.seq_count), (0x100, 3, 0x3FFF))
        self.assertEqual(RequestId.unpack(r.pack()), r)
        self.assertEqual(RequestId(0x100, 0x3FFF), r)
        self.assertEqual(hash(RequestId(0x100, 0x3FFF)), hash(r))

    def test_request_id_too_short(self):
        with self.assertRaises(PusLengthError):
            RequestId.unpack(b"\x19\x00\xff")


def _resealed(raw):
    return sealed(raw[:-2].hex())


class TestDecodeErrors(unittest.TestCase):
    def test_bad_crc(self):
        bad = TC_17_1[:-1] + bytes([TC_17_1[-1] ^ 1])
        with self.assertRaises(PusCrcError) as cm:
            PusTc.unpack(bad)
        e = cm.exception
        self.assertEqual(e.expected, crc_bitwise(TC_17_1[:-2]))
        self.assertEqual(e.actual, (bad[-2] << 8) | bad[-1])
        self.assertEqual((e.packet_id, e.sequence_control), (0x1873, 0xC019))
        self.assertEqual(e.request_id(), RequestId(0x73, 25))
        self.assertEqual(e.apid, 0x73)
        self.assertEqual(failure_code(e), messages.FAILURE_INCORRECT_CHECKSUM)

    def test_too_short_for_primary_header(self):
        with self.assertRaises(PusLengthError) as cm:
            PusTc.unpack(TC_17_1[:5])
        self.assertEqual((cm.exception.expected, cm.exception.got), (6, 5))
        self.assertIsNone(cm.exception.packet_id)
        self.assertIsNone(cm.exception.request_id())
        self.assertEqual(failure_code(cm.exception), messages.FAILURE_INVALID_LENGTH)

    def test_truncated_and_overlong(self):
        with self.assertRaises(PusLengthError) as cm:
            PusTc.unpack(TC_20_3[:-1])
        self.assertEqual((cm.exception.expected, cm.exception.got), (17, 16))
        self.assertEqual(cm.exception.packet_id, 0x1900)
        with self.assertRaises(PusLengthError) as cm:
            PusTm.unpack(TM_3_25 + b"\x00")
        self.assertEqual((cm.exception.expected, cm.exception.got), (23, 24))

    def test_data_field_shorter_than_secondary_header(self):
        raw = sealed("1873 c019 0003 2f 11")  # 4 octets: no room for header and PEC
        with self.assertRaises(PusLengthError) as cm:
            PusTc.unpack(raw)
        self.assertEqual((cm.exception.expected, cm.exception.got), (13, 10))

    def test_the_shortest_tc_exactly(self):
        # PUS-C TC: primary header 6 + secondary header 5 + PEC 2 = 13 octets at least; a
        # 12-octet TC with a good checksum is refused (its source ID would be read from the
        # checksum), on every decode path (accelerated, fast, careful)
        short = sealed("1873 c019 0005 2f 11 01 00")
        self.assertEqual(len(short), 12)
        for unpack in (PusTc.unpack, lambda b: PusTc._decode(b, 0, DEFAULT, True)[0]):
            with self.assertRaises(PusLengthError) as cm:
                unpack(short)
            self.assertEqual((cm.exception.expected, cm.exception.got), (13, 12))
            self.assertEqual(failure_code(cm.exception), messages.FAILURE_INVALID_LENGTH)
            tc = unpack(TC_17_1)
            self.assertEqual((len(TC_17_1), tc.service, tc.subtype, tc.source_id), (13, 17, 1, 0))

    def test_pus_version(self):
        raw = sealed("1873 c019 0006 1f 11 01 0000")  # PUS version 1 (PUS-A)
        with self.assertRaises(PusVersionError) as cm:
            PusTc.unpack(raw)
        self.assertEqual(cm.exception.version, 1)
        self.assertEqual(cm.exception.packet_id, 0x1873)
        self.assertEqual(failure_code(cm.exception), messages.FAILURE_UNSUPPORTED_HEADER)
        tm = bytearray(TM_3_25[:-2])
        tm[6] = 0x01  # PUS version 0
        with self.assertRaises(PusVersionError):
            PusTm.unpack(sealed(bytes(tm).hex()))

    def test_wrong_packet_type_and_flags(self):
        with self.assertRaises(PusHeaderError) as cm:
            PusTc.unpack(TM_3_25)
        self.assertEqual(cm.exception.field, "packet type")
        with self.assertRaises(PusHeaderError):
            PusTm.unpack(TC_17_1)
        no_sec = sealed("1073 c019 0006 2f 11 01 0000")
        with self.assertRaises(PusHeaderError) as cm:
            PusTc.unpack(no_sec)
        self.assertEqual(cm.exception.field, "secondary header flag")
        v1 = sealed("3873 c019 0006 2f 11 01 0000")
        with self.assertRaises(PusHeaderError) as cm:
            PusTc.unpack(v1)
        self.assertEqual(cm.exception.field, "packet version number")

    def test_mission_maximum(self):
        cfg = PusConfig(max_packet_size=20)
        with self.assertRaises(PusLengthError):
            PusTm.unpack(TM_3_25, cfg)
        with self.assertRaises(spp.FieldRangeError):
            PusTc(1, 20, 3, bytes(20), config=cfg).pack()

    def test_errors_are_value_errors(self):
        for cls in (PusCrcError, PusLengthError, PusVersionError, PusHeaderError):
            self.assertTrue(issubclass(cls, PusError))
            self.assertTrue(issubclass(cls, spp.SppError))
            self.assertTrue(issubclass(cls, ValueError))


class TestEncodeRanges(unittest.TestCase):
    def test_tc_fields_checked(self):
        for kw in (
            {"apid": 0x800},
            {"apid": -1},
            {"service": 256},
            {"subtype": -1},
            {"seq_count": 0x4000},
            {"ack": 16},
            {"source_id": 0x10000},
            {"seq_flags": 4},
        ):
            args = {"apid": 1, "service": 17, "subtype": 1}
            args.update(kw)
            with self.assertRaises(spp.FieldRangeError):
                PusTc(**args).pack()

    def test_tm_fields_checked(self):
        for kw in (
            {"time_ref": 16},
            {"message_counter": 0x10000},
            {"destination_id": -1},
            {"time": (1 << 32, 0)},
            {"time": (0, 1 << 16)},
            {"apid": 0x800},
        ):
            args = {"apid": 1, "service": 3, "subtype": 25}
            args.update(kw)
            with self.assertRaises(spp.FieldRangeError):
                PusTm(**args).pack()

    def test_time_none_packs_zero(self):
        raw = PusTm(1, 17, 2).pack()
        self.assertEqual(raw[13:19], bytes(6))
        self.assertEqual(PusTm.unpack(raw).time, (0, 0))


class TestMissionLayouts(unittest.TestCase):
    def test_no_source_id_no_pec(self):
        cfg = PusConfig(source_id_size=0, pec=False)
        tc = PusTc(0x73, 17, 1, seq_count=25, config=cfg)
        self.assertEqual(tc.pack(), bytes.fromhex("1873c01900022f1101"))
        self.assertEqual(PusTc.unpack(tc.pack(), cfg), tc)

    def test_one_octet_source_id_and_spare(self):
        cfg = PusConfig(source_id_size=1, tc_spare=1)
        tc = PusTc(0x73, 17, 1, b"\x99", seq_count=25, source_id=0x42, config=cfg)
        self.assertEqual(tc.pack(), sealed("1873 c019 0007 2f 11 01 42 00 99"))
        self.assertEqual(PusTc.unpack(tc.pack(), cfg), tc)
        self.assertEqual(cfg.tc_header_size, 5)

    def test_three_octet_ids(self):
        cfg = PusConfig(source_id_size=3, destination_id_size=3, message_counter_size=1)
        tc = PusTc(5, 17, 1, source_id=0x123456, config=cfg)
        self.assertEqual(tc.pack(), sealed("1805 c000 0007 2f 11 01 123456"))
        self.assertEqual(PusTc.unpack(tc.pack(), cfg), tc)
        tm = PusTm(5, 17, 2, b"", 1, 0xAB, 0xABCDEF, (7, 8), config=cfg)
        self.assertEqual(tm.pack(), sealed("0805 c001 000e 20 11 02 ab abcdef 00000007 0008"))
        self.assertEqual(PusTm.unpack(tm.pack(), cfg), tm)

    def test_explicit_cuc_pfield(self):
        # P-field: no extension, code 001 (1958 epoch), 4 coarse octets (11), 2 fine (10) = 0x1E
        cfg = PusConfig(time=Cuc(4, 2, explicit=True))
        tm = PusTm(0x65, 3, 25, b"\xaa\xbb", 5, 7, 9, (0x01020304, 0x0506), time_ref=1, config=cfg)
        raw = tm.pack()
        self.assertEqual(raw, sealed("0865 c005 0011 21 03 19 0007 0009 1e 01020304 0506 aabb"))
        self.assertEqual(PusTm.unpack(raw, cfg), tm)
        other = bytearray(raw[:-2])
        other[13] = 0x1D  # a P-field announcing 1 fine octet: not this mission's time code
        with self.assertRaises(PusHeaderError) as cm:
            PusTm.unpack(sealed(bytes(other).hex()), cfg)
        self.assertEqual(cm.exception.field, "time field")

    def test_cds_time_and_no_destination(self):
        cfg = PusConfig(destination_id_size=0, message_counter_size=1, time=Cds(2, 0))
        tm = PusTm(0x65, 17, 2, b"", 5, 0x7F, 0, (0x0102, 0x03040506, 0), config=cfg)
        self.assertEqual(tm.pack(), sealed("0865 c005 000b 20 11 02 7f 0102 03040506"))
        self.assertEqual(PusTm.unpack(tm.pack(), cfg), tm)

    def test_no_time_field(self):
        cfg = PusConfig(time=None, tm_spare=2)
        tm = PusTm(1, 17, 2, b"\x01", 0, 1, 2, config=cfg)
        self.assertEqual(tm.pack(), sealed("0801 c000 000b 20 11 02 0001 0002 0000 01"))
        back = PusTm.unpack(tm.pack(), cfg)
        self.assertIsNone(back.time)
        self.assertEqual(back, tm)

    def test_default_is_pus_c(self):
        self.assertEqual(DEFAULT, PusConfig())
        self.assertEqual(DEFAULT.tc_header_size, 5)
        self.assertEqual(DEFAULT.tm_header_size, 13)
        self.assertTrue(DEFAULT.pec)

    def test_bad_sizes_rejected(self):
        with self.assertRaises(ValueError):
            PusConfig(source_id_size=5)
        with self.assertRaises(ValueError):
            PusConfig(message_counter_size=3)


class TestMessages(unittest.TestCase):
    def _pairs(self):
        out = {}
        for name in dir(messages):
            value = getattr(messages, name)
            if name[:3] in ("TC_", "TM_"):
                out[name] = value
        return out

    def test_each_pair_named_once(self):
        pairs = self._pairs()
        self.assertEqual(len(set(pairs.values())), len(pairs))
        self.assertEqual(messages.TC_TEST_ARE_YOU_ALIVE, (17, 1))
        self.assertEqual(messages.TM_TEST_ARE_YOU_ALIVE_REPORT, (17, 2))
        self.assertEqual(messages.TC_PARAM_SET_VALUES, (20, 3))
        self.assertEqual(messages.TM_VERIFY_ROUTING_FAILURE, (1, 10))

    def test_services_covered(self):
        services = set(v[0] for v in self._pairs().values())
        expected = (1, 2, 3, 4, 5, 6, 8, 9, 11, 12, 13, 14, 15, 17, 18, 19, 20, 21, 22, 23)
        self.assertEqual(sorted(services), list(expected))
        counts = {}
        for v in self._pairs().values():
            counts[v[0]] = counts.get(v[0], 0) + 1
        self.assertEqual(counts[1], 9)
        self.assertEqual(counts[17], 4)
        self.assertEqual(counts[11], 27)
        self.assertEqual(counts[23], 24)

    def test_failure_codes_distinct(self):
        codes = [getattr(messages, n) for n in dir(messages) if n.startswith("FAILURE_")]
        self.assertEqual(len(set(codes)), len(codes))
        self.assertEqual(messages.FAILURE_INCORRECT_CHECKSUM, 2)


class TestRequestIdAndTypeBit(unittest.TestCase):
    def test_the_fields_of_a_request_id(self):
        r = RequestId.from_words(0x1873, 0xC019)
        self.assertEqual((r.version, r.packet_type, r.sec_header_flag, r.apid), (0, 1, 1, 0x73))
        self.assertEqual((r.seq_flags, r.seq_count), (3, 25))
        self.assertEqual(RequestId.from_words(0x1073, 0xC019).sec_header_flag, 0)
        self.assertEqual(RequestId.from_words(0x3873, 0xC019).version, 1)  # its 3 top bits
        self.assertEqual(RequestId.from_words(0xF873, 0xC019).version, 7)

    def test_equal_only_when_both_words_are(self):
        r = RequestId.from_words(0x1873, 0xC019)
        self.assertEqual(r, RequestId.from_words(0x1873, 0xC019))
        self.assertNotEqual(r, RequestId.from_words(0x1873, 0xC01A))
        self.assertNotEqual(r, RequestId.from_words(0x1874, 0xC019))

    def test_the_packet_type_bit_alone_chooses_tc_or_tm(self):
        # APID 0x100 sets the lowest bit of the first octet, next to the type bit
        tm = PusTm(0x100, 17, 2).pack()
        self.assertEqual(tm[0] & 0x11, 0x01)
        got = unpack_packet(tm)
        self.assertTrue(isinstance(got, PusTm))
        self.assertEqual((got.apid, got.service, got.subtype), (0x100, 17, 2))


if __name__ == "__main__":
    unittest.main()
