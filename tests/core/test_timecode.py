"""CCSDS 301.0-B-4 CUC and CDS time codes: P-fields, T-fields, seconds and UTC helpers."""

import unittest

from obsw import timecode as tc
from obsw import utc
from obsw.timecode import Cds, Cuc


class TestCucPField(unittest.TestCase):
    def test_level1_pfields(self):
        # 301.0-B-4 3.2.2: ext | id 001 | coarse-1 (2 bits) | fine (2 bits)
        self.assertEqual(Cuc(4, 2).pfield(), bytes([0b00011110]))
        self.assertEqual(Cuc(4, 3).pfield(), b"\x1f")
        self.assertEqual(Cuc(1, 0).pfield(), b"\x10")
        self.assertEqual(Cuc(2, 1).pfield(), b"\x15")

    def test_agency_epoch_sets_code_010(self):
        self.assertEqual(Cuc(4, 2, epoch=0).pfield(), b"\x2e")
        self.assertEqual(Cuc(4, 2, epoch=0).code, tc.CODE_CUC_AGENCY)

    def test_extension_octet(self):
        # second octet: ext | extra coarse (2 bits) | extra fine (3 bits) | 2 reserved bits
        self.assertEqual(Cuc(5, 4).pfield(), bytes([0x9F, 0b00100100]))
        self.assertEqual(Cuc(7, 10).pfield(), bytes([0x9F, 0b01111100]))
        self.assertEqual(Cuc(4, 5).pfield(), bytes([0x9F, 0b00001000]))
        self.assertEqual(Cuc(7, 10, explicit=True).size, 19)

    def test_from_pfield_all_sizes(self):
        for coarse in range(1, 8):
            for fine in range(11):
                for epoch in (None, 86400):
                    c = Cuc(coarse, fine, epoch, explicit=True)
                    got, n = Cuc.from_pfield(c.pfield() + b"\x00" * 20, agency_epoch=86400)
                    self.assertEqual(got, c)
                    self.assertEqual(n, len(c.pfield()))

    def test_from_pfield_rejects(self):
        with self.assertRaises(tc.TimeCodeFormatError):
            Cuc.from_pfield(b"\x40")  # CDS id
        with self.assertRaises(tc.TimeCodeFormatError):
            Cuc.from_pfield(b"\x9f\x80")  # third octet
        with self.assertRaises(tc.TimeCodeTooShortError):
            Cuc.from_pfield(b"\x9f")
        with self.assertRaises(tc.TimeCodeTooShortError):
            Cuc.from_pfield(b"")

    def test_bad_configuration(self):
        for coarse, fine in ((0, 0), (8, 0), (4, 11), (4, -1)):
            with self.assertRaises(tc.TimeCodeFormatError):
                Cuc(coarse, fine)


class TestCucTField(unittest.TestCase):
    def test_pack_implicit(self):
        self.assertEqual(Cuc(4, 2).pack(0x01020304, 0x8000), bytes.fromhex("010203048000"))
        self.assertEqual(Cuc(4, 0).pack(7), bytes.fromhex("00000007"))
        self.assertEqual(Cuc(3, 1).pack(0x010203, 0x40), bytes.fromhex("01020340"))

    def test_pack_explicit(self):
        c = Cuc(4, 2, explicit=True)
        self.assertEqual(c.size, 7)
        self.assertEqual(c.pack(1, 2), bytes.fromhex("1e000000010002"))
        self.assertEqual(c.unpack(bytes.fromhex("ff1e000000010002"), 1), (1, 2))

    def test_round_trip_all_sizes(self):
        for coarse in range(1, 8):
            for fine in range(11):
                for explicit in (False, True):
                    c = Cuc(coarse, fine, explicit=explicit)
                    cv = (1 << (8 * coarse)) - 2
                    fv = (1 << (8 * fine)) - 1
                    b = c.pack(cv, fv)
                    self.assertEqual(len(b), c.size)
                    self.assertEqual(c.unpack(b), (cv, fv))

    def test_errors(self):
        c = Cuc(2, 1, explicit=True)
        with self.assertRaises(tc.TimeValueError) as cm:
            c.pack(65536, 0)
        self.assertEqual(cm.exception.maximum, 65535)
        with self.assertRaises(tc.TimeValueError):
            c.pack(0, 256)
        with self.assertRaises(tc.TimeCodeTooShortError) as cm:
            c.unpack(b"\x15\x00\x00")
        self.assertEqual((cm.exception.needed, cm.exception.got), (4, 3))
        with self.assertRaises(tc.PFieldMismatchError) as cm:
            c.unpack(b"\x1e\x00\x00\x00")
        self.assertEqual(cm.exception.expected, b"\x15")
        self.assertTrue(isinstance(cm.exception, ValueError))

    def test_seconds(self):
        c = Cuc(4, 2)
        self.assertEqual(c.pack_seconds(1.5), bytes.fromhex("000000018000"))
        self.assertEqual(c.unpack_seconds(bytes.fromhex("000000014000")), 1.25)
        self.assertEqual(c.pack_seconds(10), bytes.fromhex("0000000a0000"))
        # rounding up to the next whole second carries into the coarse time
        self.assertEqual(c.from_seconds(2.9999999), (3, 0))
        self.assertEqual(Cuc(4, 0).unpack_seconds(b"\x00\x00\x01\x00"), 256)

    def test_epoch_offset(self):
        c = Cuc(4, 2, epoch=utc.utc_to_tai(2000, 1, 1))
        self.assertEqual(c.epoch_offset, c.epoch)
        self.assertEqual(c.code, 2)


class TestCds(unittest.TestCase):
    def test_pfields(self):
        self.assertEqual(Cds().pfield(), b"\x40")
        self.assertEqual(Cds(2, 2).pfield(), b"\x41")
        self.assertEqual(Cds(3, 4).pfield(), b"\x46")
        self.assertEqual(Cds(2, 2, epoch=0).pfield(), b"\x49")

    def test_pack(self):
        self.assertEqual(Cds().pack(1, 2), bytes.fromhex("000100000002"))
        self.assertEqual(Cds(2, 2).pack(1, 2, 999), bytes.fromhex("00010000000203e7"))
        self.assertEqual(
            Cds(3, 4, explicit=True).pack(0x10203, 5, 999999999),
            bytes.fromhex("46010203000000053b9ac9ff"),
        )

    def test_round_trip_all_formats(self):
        for day_octets in (2, 3):
            for sub in (0, 2, 4):
                for epoch in (None, 0):
                    for explicit in (False, True):
                        c = Cds(day_octets, sub, epoch, explicit)
                        t = ((1 << (8 * day_octets)) - 1, 86400999, c.sub_per_ms - 1)
                        b = c.pack(*t)
                        self.assertEqual(len(b), c.size)
                        self.assertEqual(c.unpack(b"\xaa" + b, 1), t)
                        if explicit:
                            got, n = tc.from_pfield(b, agency_epoch=0)
                            self.assertEqual((got, n), (c, 1))

    def test_ranges(self):
        c = Cds(2, 2)
        with self.assertRaises(tc.TimeValueError):
            c.pack(0, 86401000)
        with self.assertRaises(tc.TimeValueError):
            c.pack(0, 0, 1000)
        with self.assertRaises(tc.TimeValueError):
            c.pack(65536, 0)
        with self.assertRaises(tc.TimeValueError):
            c.unpack(bytes.fromhex("00000526 5c0003e8"))
        with self.assertRaises(tc.TimeCodeTooShortError):
            c.unpack(b"\x00" * 7)
        with self.assertRaises(tc.PFieldMismatchError):
            Cds(explicit=True).unpack(b"\x41" + b"\x00" * 6)

    def test_from_pfield_rejects(self):
        with self.assertRaises(tc.TimeCodeFormatError):
            Cds.from_pfield(b"\x43")  # reserved resolution
        with self.assertRaises(tc.TimeCodeFormatError):
            Cds.from_pfield(b"\x1e")
        with self.assertRaises(tc.TimeCodeFormatError):
            tc.from_pfield(b"\x50")  # CCS is not supported here
        with self.assertRaises(tc.TimeCodeTooShortError):
            tc.from_pfield(b"")

    def test_seconds(self):
        c = Cds(2, 2)
        self.assertEqual(c.from_seconds(86400 + 1.5), (1, 1500, 0))
        self.assertEqual(c.from_seconds(2 * 86400 + 3), (2, 3000, 0))
        self.assertEqual(c.to_seconds(2, 3000), 2 * 86400 + 3)
        self.assertAlmostEqual(c.unpack_seconds(c.pack_seconds(100.000123)), 100.000123)


class TestUtc(unittest.TestCase):
    def test_epochs(self):
        self.assertEqual(utc.utc_to_tai(1958, 1, 1), 10)  # before 1972: approximated by 10 s
        # 2017-01-01 00:00:00 UTC: 21550 days after 1958, TAI-UTC 37 s
        self.assertEqual(utc.utc_to_tai(2017, 1, 1), 21550 * 86400 + 37)
        self.assertEqual(utc.days_from_civil(2000, 1, 1), 15340)
        self.assertEqual(utc.civil_from_days(15340), (2000, 1, 1))

    def test_leap_second(self):
        t = utc.utc_to_tai(2016, 12, 31, 23, 59, 60)
        self.assertEqual(utc.tai_to_utc(t), (2016, 12, 31, 23, 59, 60))
        self.assertEqual(utc.tai_to_utc(t + 1), (2017, 1, 1, 0, 0, 0))
        self.assertEqual(utc.tai_to_utc(t - 1), (2016, 12, 31, 23, 59, 59))
        self.assertEqual(utc.format_utc(t + 0.5), "2016-12-31T23:59:60.500Z")

    def test_format_parse(self):
        for text in ("2024-02-29T12:34:56.789Z", "1999-12-31T23:59:59.000Z"):
            self.assertEqual(utc.format_utc(utc.parse_utc(text)), text)
        self.assertEqual(
            utc.format_utc(utc.parse_utc("2024-01-01 00:00:00"), 0), "2024-01-01T00:00:00Z"
        )
        with self.assertRaises(tc.TimeCodeFormatError):
            utc.parse_utc("yesterday")
