"""PUS packet field types PTC 6 (bit-string), 7 (octet-string), 8 (character) and 12 (packet)."""

import unittest

from obsw.bits import BitsTooShortError, Decoder, Encoder
from obsw.pus.fields import FieldTypeError, FieldValueError, field

# Space packets: a TC (type bit set, APID 0x73, count 25, 7 octets of data field) and a TM.
TC_17_1 = bytes.fromhex("1873c0190006") + bytes.fromhex("2f110100000000")
TM = bytes.fromhex("0873c0000002") + bytes.fromhex("201102")


class TestBitString(unittest.TestCase):
    def test_fixed(self):
        f = field(6, 12)
        self.assertEqual(f.bits, 12)
        self.assertEqual(f.pack(0xABC), b"\xab\xc0")
        self.assertEqual(f.unpack(b"\xab\xcf"), 0xABC)
        with self.assertRaises(FieldValueError):
            f.pack(0x1000)

    def test_variable_with_mission_prefix(self):
        f = field(6, 0, length_bits=8)
        self.assertIsNone(f.bits)
        self.assertEqual(f.pack((4, 0b1010)), b"\x04\xa0")
        self.assertEqual(f.unpack(b"\x04\xa0"), (4, 10))
        self.assertEqual(field(6, 0).pack((0, 0)), b"\x00\x00")  # default 16-bit count
        self.assertEqual(field(6, 0).pack((9, 0x1FF)), b"\x00\x09\xff\x80")

    def test_variable_limits(self):
        f = field(6, 0, length_bits=8, max_length=16)
        with self.assertRaises(FieldValueError):
            f.pack((17, 0))
        with self.assertRaises(FieldValueError):
            f.unpack(b"\x11" + b"\x00" * 4)
        with self.assertRaises(FieldValueError):
            f.pack((3, 8))
        with self.assertRaises(BitsTooShortError):
            f.unpack(b"\x10\x00")
        with self.assertRaises(FieldTypeError):
            field(6, 0, length_bits=0)
        with self.assertRaises(FieldTypeError):
            field(6, 0, length_bits=8, max_length=256)
        with self.assertRaises(FieldTypeError):
            field(6, 0, colour="red")


class TestOctetString(unittest.TestCase):
    def test_fixed(self):
        f = field(7, 3)
        self.assertEqual(f.bits, 24)
        self.assertEqual(f.pack(b"abc"), b"abc")
        self.assertEqual(f.unpack(b"abcd"), b"abc")
        with self.assertRaises(FieldValueError):
            f.pack(b"ab")
        with self.assertRaises(FieldValueError):
            f.pack("abc")

    def test_variable(self):
        self.assertEqual(field(7, 0).pack(b"abc"), b"\x00\x03abc")
        self.assertEqual(field(7, 0, length_bits=8).pack(b""), b"\x00")
        self.assertEqual(field(7, 0).unpack(b"\x00\x02xyz"), b"xy")
        self.assertEqual(field(7, 0).pack(bytearray(b"\x01")), b"\x00\x01\x01")
        with self.assertRaises(FieldValueError):
            field(7, 0, length_bits=8, max_length=2).pack(b"abc")
        with self.assertRaises(BitsTooShortError):
            field(7, 0).unpack(b"\x00\x05ab")

    def test_unaligned(self):
        e = Encoder()
        field(1, 0).write(e, True)
        field(7, 0, length_bits=8).write(e, b"\xff")
        self.assertEqual(e.getvalue(), b"\x80\xff\x80")
        d = Decoder(e.getvalue())
        self.assertIs(field(1, 0).read(d), True)
        self.assertEqual(field(7, 0, length_bits=8).read(d), b"\xff")


class TestCharacterString(unittest.TestCase):
    def test_fixed_and_variable(self):
        self.assertEqual(field(8, 5).pack("hello"), b"hello")
        self.assertEqual(field(8, 5).unpack(b"hello!"), "hello")
        self.assertEqual(field(8, 0).pack("ok"), b"\x00\x02ok")
        self.assertEqual(field(8, 0).unpack(b"\x00\x02ok"), "ok")
        # lengths count octets
        self.assertEqual(field(8, 0, length_bits=8).pack("\u00e9"), b"\x02\xc3\xa9")

    def test_errors(self):
        with self.assertRaises(FieldValueError):
            field(8, 5).pack("hell")
        with self.assertRaises(FieldValueError):
            field(8, 0).pack(5)
        with self.assertRaises(FieldValueError):
            field(8, 2).unpack(b"\xff\xfe")


class TestPacket(unittest.TestCase):
    def test_tc_field(self):
        f = field(12, 0)
        self.assertEqual(f.pack(TC_17_1), TC_17_1)
        self.assertEqual(f.unpack(TC_17_1 + b"trailing"), TC_17_1)

    def test_tm_field_and_codec(self):
        class Raw:
            def __init__(self, data):
                self.data = data

            def pack(self):
                return self.data

            @classmethod
            def unpack(cls, buf):
                return cls(bytes(buf))

        f = field(12, 1, codec=Raw)
        self.assertEqual(f.pack(Raw(TM)), TM)
        self.assertEqual(f.unpack(TM).data, TM)

    def test_packet_in_a_structure_at_offset(self):
        e = Encoder()
        field(3, 4).write(e, 2)
        field(12, 0).write(e, TC_17_1)
        field(12, 1).write(e, TM)
        d = Decoder(e.getvalue())
        self.assertEqual(field(3, 4).read(d), 2)
        self.assertEqual(field(12, 0).read(d), TC_17_1)
        self.assertEqual(field(12, 1).read(d), TM)

    def test_errors(self):
        with self.assertRaises(FieldValueError):
            field(12, 1).pack(TC_17_1)  # a TC where a TM belongs
        with self.assertRaises(FieldValueError):
            field(12, 0).pack(TC_17_1[:-1])  # length field disagrees
        with self.assertRaises(FieldValueError):
            field(12, 0).pack(42)
        with self.assertRaises(BitsTooShortError):
            field(12, 0).unpack(TC_17_1[:-1])
        with self.assertRaises(FieldValueError):
            field(12, 0).unpack(TM)
