"""PUS packet fields at their edges: all-ones APID, sequence count and version, the length field
one off either way, and the errors that name what was wrong."""

import unittest

from obsw.pus.any_packet import unpack_packet
from obsw.pus.config import PusConfig
from obsw.pus.packets import (
    PusCrcError,
    PusHeaderError,
    PusLengthError,
    PusTooShortError,
    PusVersionError,
    RequestId,
)
from obsw.pus.tc import PusTc
from obsw.pus.tm import PusTm
from obsw.spp import FieldRangeError
from pus_sealed import crc_bitwise, resealed


class TestAllOnesFields(unittest.TestCase):
    def test_tc_apid_and_sequence_count_all_ones(self):
        raw = PusTc(0x7FF, 17, 1, b"ab", seq_count=0x3FFF, ack=15, source_id=0xFFFF).pack()
        tc = PusTc.unpack(raw)
        self.assertEqual(
            (tc.apid, tc.seq_count, tc.ack, tc.source_id), (0x7FF, 0x3FFF, 15, 0xFFFF)
        )
        self.assertEqual(tc.data, b"ab")
        self.assertEqual(tc.seq_flags, 3)
        for flags in (0, 1, 2):
            self.assertEqual(
                PusTc.unpack(PusTc(1, 17, 1, seq_flags=flags).pack()).seq_flags, flags
            )

    def test_tc_apid_and_sequence_count_one_below_all_ones(self):
        tc = PusTc.unpack(PusTc(0x7FE, 17, 1, b"", seq_count=0x3FFE).pack())
        self.assertEqual((tc.apid, tc.seq_count), (0x7FE, 0x3FFE))

    def test_request_id_fields_from_all_ones_words(self):
        r = RequestId.from_words(0xFFFF, 0xFFFF)
        self.assertEqual((r.version, r.packet_type, r.sec_header_flag), (7, 1, 1))
        self.assertEqual((r.apid, r.seq_flags, r.seq_count), (0x7FF, 3, 0x3FFF))
        self.assertEqual(RequestId.from_words(0x1FFF, 0).version, 0)
        self.assertEqual(RequestId.from_words(0x2000, 0).version, 1)

    def test_request_ids_that_differ_hash_apart(self):
        # the hash is the 32-bit request ID itself: no two IDs share one
        pairs = ((0x0001, 0x0000), (0x0000, 0x8000), (0x0000, 0xFFFF), (0x0001, 0x7FFF))
        hashes = set(hash(RequestId.from_words(p, s)) for p, s in pairs)
        self.assertEqual(len(hashes), len(pairs))
        a, b = RequestId.from_words(0x1FFF, 0xC000), RequestId.from_words(0x1FFF, 0xC000)
        self.assertEqual((a, hash(a)), (b, hash(b)))


class TestLengthField(unittest.TestCase):
    def test_length_field_one_above_the_packet(self):
        raw = bytearray(PusTc(0x10, 17, 1, b"abcd").pack())
        dlen = raw[4] << 8 | raw[5]
        raw[4:6] = bytes(((dlen + 1) >> 8, (dlen + 1) & 0xFF))
        with self.assertRaises(PusLengthError):
            PusTc.unpack(resealed(raw[:-2]))

    def test_length_field_one_below_the_packet(self):
        raw = bytearray(PusTc(0x10, 17, 1, b"abcd").pack())
        dlen = raw[4] << 8 | raw[5]
        raw[4:6] = bytes(((dlen - 1) >> 8, (dlen - 1) & 0xFF))
        with self.assertRaises(PusLengthError):
            PusTc.unpack(resealed(raw[:-2]))

    def test_length_field_exact(self):
        self.assertEqual(PusTc.unpack(PusTc(0x10, 17, 1, b"abcd").pack()).data, b"abcd")


class TestPec(unittest.TestCase):
    def test_a_pec_computed_from_another_preset_is_refused(self):
        # CRC-16/CCITT-FALSE starts from all ones; a PEC from 0xFFFE (one bit off) is wrong
        body = PusTc(0x10, 17, 1, b"abcd").pack()[:-2]
        reg = 0xFFFE
        for byte in body:
            reg ^= byte << 8
            for _ in range(8):
                reg = ((reg << 1) ^ 0x1021) & 0xFFFF if reg & 0x8000 else (reg << 1) & 0xFFFF
        with self.assertRaises(PusCrcError):
            PusTc.unpack(body + bytes((reg >> 8, reg & 0xFF)))

    def test_a_pec_that_leaves_a_remainder_of_one_is_refused(self):
        # the check over packet and PEC must come to 0; 0x9D71 fed into a cleared register
        # leaves 1, so the right PEC XOR 0x9D71 leaves a remainder of exactly 1
        body = PusTc(0x10, 17, 1, b"abcd").pack()[:-2]
        pec = crc_bitwise(body) ^ 0x9D71
        with self.assertRaises(PusCrcError):
            PusTc.unpack(body + bytes((pec >> 8, pec & 0xFF)))


class TestPusVersion(unittest.TestCase):
    def test_only_version_2_is_a_pus_c_tc(self):
        body = bytearray(PusTc(0x10, 17, 1, b"abcd").pack()[:-2])
        for version in [v for v in range(16) if v != 2]:
            for ack in (0, 0xF):
                body[6] = version << 4 | ack
                with self.assertRaises(PusVersionError) as cm:
                    PusTc.unpack(resealed(body))
                self.assertEqual(cm.exception.version, version)


class TestHeaderErrorsNameTheValue(unittest.TestCase):
    def test_a_tm_given_as_tc_names_its_packet_type(self):
        raw = PusTm(0x10, 1, 1, b"").pack()
        with self.assertRaises(PusHeaderError) as cm:
            PusTc.unpack(raw)
        e = cm.exception
        self.assertEqual((e.field, e.expected, e.actual), ("packet type", 1, 0))

    def test_a_tc_given_as_tm_names_its_packet_type(self):
        raw = PusTc(0x10, 17, 1, b"").pack()
        with self.assertRaises(PusHeaderError) as cm:
            PusTm.unpack(raw)
        e = cm.exception
        self.assertEqual((e.field, e.expected, e.actual), ("packet type", 0, 1))

    def test_no_secondary_header_flag(self):
        raw = bytearray(PusTc(0x10, 17, 1, b"").pack())
        raw[0] &= ~0x08
        with self.assertRaises(PusHeaderError) as cm:
            PusTc.unpack(resealed(raw[:-2]))
        e = cm.exception
        self.assertEqual((e.field, e.expected, e.actual), ("secondary header flag", 1, 0))


class TestRequestIdBuffer(unittest.TestCase):
    def test_four_octets_from_the_offset(self):
        r = RequestId.unpack(b"\x00\x00\x18\x05\xc0\x07", 2)
        self.assertEqual((r.apid, r.seq_count), (5, 7))

    def test_three_octets_from_the_offset(self):
        with self.assertRaises(PusTooShortError) as cm:
            RequestId.unpack(b"\x00\x00\x18\x05\xc0", 2)
        self.assertEqual((cm.exception.needed, cm.exception.got), (4, 3))


class TestPackRangeErrorsNameTheField(unittest.TestCase):
    def field(self, **kw):
        args = dict(apid=0, service=0, subtype=0, data=b"", seq_count=0, ack=0, seq_flags=0)
        args.update(kw)
        with self.assertRaises(FieldRangeError) as cm:
            PusTc(**args).pack()
        return cm.exception.field, cm.exception.value

    def test_zero_fields_pass_and_the_wrong_one_is_named(self):
        self.assertEqual(self.field(seq_count=0x4000), ("sequence count", 0x4000))
        self.assertEqual(self.field(apid=0x800), ("APID", 0x800))

    def test_a_negative_field_or_an_octet_of_256_is_named(self):
        for kw, named in (
            ({"apid": -1}, ("APID", -1)),
            ({"seq_count": -1}, ("sequence count", -1)),
            ({"seq_flags": -1}, ("sequence flags", -1)),
            ({"ack": -1}, ("acknowledgement flags", -1)),
            ({"service": 256}, ("service type", 256)),
            ({"subtype": 256}, ("message subtype", 256)),
        ):
            self.assertEqual(self.field(**kw), named)

    def test_sequence_flags_3_are_in_range(self):
        self.assertEqual(self.field(seq_flags=3, ack=16), ("acknowledgement flags", 16))
        self.assertEqual(self.field(seq_flags=4), ("sequence flags", 4))

    def test_a_three_octet_source_id_at_its_limit(self):
        c = PusConfig(source_id_size=3)
        tc = PusTc.unpack(PusTc(1, 17, 1, b"x", source_id=0xFFFFFF, config=c).pack(), c)
        self.assertEqual(tc.source_id, 0xFFFFFF)
        with self.assertRaises(FieldRangeError) as cm:
            PusTc(1, 17, 1, b"x", source_id=0x1000000, config=c).pack()
        self.assertEqual(cm.exception.field, "source ID")


class TestUnpackPacket(unittest.TestCase):
    def test_one_octet_with_the_tc_bit_is_a_short_tc(self):
        with self.assertRaises(PusTooShortError) as cm:
            unpack_packet(b"\x18")
        self.assertTrue(str(cm.exception).startswith("TC"), str(cm.exception))

    def test_one_octet_without_it_is_a_short_tm(self):
        with self.assertRaises(PusTooShortError) as cm:
            unpack_packet(b"\x08")
        self.assertTrue(str(cm.exception).startswith("TM"), str(cm.exception))

    def test_nothing_is_a_short_tm(self):
        with self.assertRaises(PusTooShortError):
            unpack_packet(b"")


if __name__ == "__main__":
    unittest.main()
