"""PUS packet field types PTC 9 (absolute time) and PTC 10 (relative time)."""

import unittest

from obsw.bits import BitsTooShortError, Decoder, Encoder
from obsw.pus.fields import FieldTypeError, FieldValueError, field
from obsw.pus.ptc_time import cuc_octets, cuc_pfc
from obsw.timecode import Cds, Cuc, TimeCodeError


class TestPfcTable(unittest.TestCase):
    def test_cuc_pfcs(self):
        # PFC 3..18: (PFC + 1) // 4 coarse and (PFC + 1) % 4 fine octets
        self.assertEqual(cuc_octets(3), (1, 0))
        self.assertEqual(cuc_octets(6), (1, 3))
        self.assertEqual(cuc_octets(7), (2, 0))
        self.assertEqual(cuc_octets(17), (4, 2))
        self.assertEqual(cuc_octets(18), (4, 3))
        # PFC 19..46: the fine times of 4..10 octets
        self.assertEqual(cuc_octets(19), (1, 4))
        self.assertEqual(cuc_octets(25), (1, 10))
        self.assertEqual(cuc_octets(26), (2, 4))
        self.assertEqual(cuc_octets(46), (4, 10))

    def test_every_cuc_pair_has_one_pfc(self):
        seen = set()
        for coarse in range(1, 5):
            for fine in range(11):
                pfc = cuc_pfc(coarse, fine)
                self.assertEqual(cuc_octets(pfc), (coarse, fine))
                seen.add(pfc)
        self.assertEqual(sorted(seen), list(range(3, 47)))
        with self.assertRaises(FieldTypeError):
            cuc_pfc(5, 0)
        with self.assertRaises(FieldTypeError):
            cuc_octets(47)

    def test_widths(self):
        self.assertEqual(field(9, 1).bits, 48)
        self.assertEqual(field(9, 2).bits, 64)
        self.assertEqual(field(9, 17).bits, 48)
        self.assertEqual(field(9, 46).bits, 112)
        self.assertIsNone(field(9, 0).bits)
        self.assertEqual(field(10, 3).bits, 8)
        for ptc, pfc in ((9, 47), (10, 0), (10, 1), (10, 47), (9, -1)):
            with self.assertRaises(FieldTypeError):
                field(ptc, pfc)


class TestAbsolute(unittest.TestCase):
    def test_cds(self):
        self.assertEqual(field(9, 1).pack((1, 2)), bytes.fromhex("000100000002"))
        self.assertEqual(field(9, 1).unpack(bytes.fromhex("000100000002")), (1, 2, 0))
        self.assertEqual(field(9, 2).pack((1, 2, 3)), bytes.fromhex("0001000000020003"))
        self.assertEqual(field(9, 2).pack(86400.5), bytes.fromhex("00010000 01f40000"))

    def test_cuc(self):
        f = field(9, 17)
        self.assertEqual(f.pack((0x01020304, 0x8000)), bytes.fromhex("010203048000"))
        self.assertEqual(f.pack(2.5), bytes.fromhex("000000028000"))
        self.assertEqual(f.unpack(bytes.fromhex("000000028000")), (2, 0x8000))
        self.assertEqual(f.seconds((2, 0x8000)), 2.5)
        self.assertEqual(field(9, 3).pack(255), b"\xff")
        self.assertEqual(field(9, 46).pack((1, 1)), bytes.fromhex("00000001") + bytes(9) + b"\x01")

    def test_agency_epoch(self):
        f = field(9, 17, epoch=1234)
        self.assertEqual(f.code.epoch, 1234)
        self.assertIsNot(f, field(9, 17))

    def test_range_errors(self):
        with self.assertRaises(FieldValueError):
            field(9, 3).pack(256)
        with self.assertRaises(FieldValueError):
            field(9, 1).pack((0, 86401000))
        with self.assertRaises(FieldValueError):
            field(9, 17).pack("noon")
        with self.assertRaises(FieldValueError):
            field(9, 17).pack((1, 2, 3))
        with self.assertRaises(TimeCodeError):
            field(9, 1).unpack(bytes.fromhex("0000ffffffff"))  # ms of day out of range
        with self.assertRaises(BitsTooShortError):
            field(9, 17).unpack(b"\x00" * 5)


class TestExplicit(unittest.TestCase):
    def test_cuc_with_pfield(self):
        f = field(9, 0)
        code = Cuc(4, 2)
        self.assertEqual(f.pack((code, (1, 2))), bytes.fromhex("1e000000010002"))
        got_code, comps = f.unpack(bytes.fromhex("1e000000010002"))
        self.assertEqual((got_code.coarse, got_code.fine, comps), (4, 2, (1, 2)))

    def test_extended_cuc_and_cds(self):
        f = field(9, 0)
        for code, comps in ((Cuc(7, 10), (5, 6)), (Cds(3, 4), (1, 2, 3)), (Cds(), (7, 8, 0))):
            data = f.pack((code, comps))
            self.assertEqual(len(data), code.tsize + len(code.pfield()))
            got_code, got = f.unpack(data)
            self.assertEqual(got, comps)
            self.assertEqual(got_code.pfield(), code.pfield())

    def test_default_code(self):
        f = field(9, 0, default_code=Cds(2, 2))
        self.assertEqual(f.pack((1, 2, 3)), bytes.fromhex("410001000000020003"))
        with self.assertRaises(FieldValueError):
            field(9, 0).pack((1, 2))  # no default: the code is needed

    def test_at_bit_offset(self):
        e = Encoder()
        field(2, 4).write(e, 9)
        field(9, 0).write(e, (Cuc(2, 1), (0x1234, 0x56)))
        d = Decoder(e.getvalue())
        self.assertEqual(field(2, 4).read(d), 9)
        self.assertEqual(field(9, 0).read(d)[1], (0x1234, 0x56))

    def test_errors(self):
        with self.assertRaises(TimeCodeError):
            field(9, 0).unpack(b"\x50\x00")  # CCS is not supported
        with self.assertRaises(BitsTooShortError):
            field(9, 0).unpack(b"\x1e\x00\x00")
        with self.assertRaises(BitsTooShortError):
            field(9, 0).unpack(b"")


class TestRelative(unittest.TestCase):
    def test_signed_cuc(self):
        f = field(10, 17)
        self.assertEqual(f.pack(-0.5), bytes.fromhex("ffffffff8000"))
        self.assertEqual(f.unpack(bytes.fromhex("ffffffff8000")), (-1, 0x8000))
        self.assertEqual(f.seconds((-1, 0x8000)), -0.5)
        self.assertEqual(f.pack(3), bytes.fromhex("000000030000"))
        self.assertEqual(f.unpack(bytes.fromhex("7fffffffffff")), (2**31 - 1, 0xFFFF))
        self.assertEqual(f.unpack(bytes.fromhex("800000000000")), (-(2**31), 0))

    def test_range(self):
        f = field(10, 3)  # one octet of seconds
        self.assertEqual(f.pack(-128), b"\x80")
        self.assertEqual(f.pack(127), b"\x7f")
        with self.assertRaises(FieldValueError):
            f.pack(128)
        with self.assertRaises(FieldValueError):
            field(10, 17).pack((0, 70000))
        with self.assertRaises(FieldValueError):
            field(10, 17).pack(None)
