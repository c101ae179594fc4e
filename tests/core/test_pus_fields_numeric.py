"""PUS packet field types PTC 1-5 against the ECSS-E-ST-70-41C definitions."""

import unittest

from obsw.bits import BitsTooShortError, Decoder, Encoder
from obsw.pus.fields import INTEGER_BITS, FieldTypeError, FieldValueError, field, int_pfc, uint_pfc


class TestLookup(unittest.TestCase):
    def test_unknown_pairs(self):
        for ptc, pfc in (
            (0, 0),
            (13, 0),
            (1, 2),
            (2, 0),
            (2, 17),
            (3, 20),
            (4, 17),
            (5, 0),
            (5, 5),
            (9, 47),
            (10, 0),
            (11, 1),
            (12, 2),
            (1, True),
        ):
            with self.assertRaises(FieldTypeError):
                field(ptc, pfc)

    def test_errors_are_value_errors(self):
        with self.assertRaises(ValueError):
            field(3, 99)
        self.assertTrue(issubclass(FieldValueError, ValueError))

    def test_cached(self):
        self.assertIs(field(3, 14), field(3, 14))

    def test_no_mission_parameters_on_numeric(self):
        with self.assertRaises(FieldTypeError):
            field(3, 14, length_bits=8)

    def test_pfc_helpers(self):
        self.assertEqual(uint_pfc(8), 4)
        self.assertEqual(uint_pfc(16), 12)
        self.assertEqual(uint_pfc(32), 14)
        self.assertEqual(uint_pfc(1), 17)
        self.assertEqual(int_pfc(64), 16)
        with self.assertRaises(FieldTypeError):
            int_pfc(3)
        with self.assertRaises(FieldTypeError):
            uint_pfc(17)


class TestBoolean(unittest.TestCase):
    def test_one_bit(self):
        b = field(1, 0)
        self.assertEqual(b.bits, 1)
        self.assertEqual(b.pack(True), b"\x80")
        self.assertEqual(b.pack(False), b"\x00")
        self.assertIs(b.unpack(b"\x80"), True)
        self.assertIs(b.unpack(b"\x7f"), False)

    def test_octet_boolean(self):
        b = field(1, 8)
        self.assertEqual(b.pack(True), b"\x01")
        self.assertIs(b.unpack(b"\x02"), True)  # any non-zero value is TRUE

    def test_rejects_non_booleans(self):
        with self.assertRaises(FieldValueError):
            field(1, 0).pack(2)
        with self.assertRaises(FieldValueError):
            field(1, 0).pack("yes")


class TestEnumerated(unittest.TestCase):
    def test_width_is_pfc(self):
        for pfc in list(range(1, 17)) + [24, 32, 48, 64]:
            self.assertEqual(field(2, pfc).bits, pfc)

    def test_vectors(self):
        self.assertEqual(field(2, 3).pack(5), b"\xa0")
        self.assertEqual(field(2, 8).pack(0x7E), b"\x7e")
        self.assertEqual(field(2, 24).pack(0x010203), b"\x01\x02\x03")
        self.assertEqual(field(2, 12).unpack(b"\xab\xcd"), 0xABC)

    def test_range(self):
        with self.assertRaises(FieldValueError) as cm:
            field(2, 3).pack(8)
        self.assertIn("0..7", str(cm.exception))
        self.assertEqual(cm.exception.value, 8)


class TestIntegers(unittest.TestCase):
    def test_unsigned_widths(self):
        # ECSS-E-ST-70-41C: PFC 0-12 are 4-16 bits, 13: 24, 14: 32, 15: 48, 16: 64;
        # 17-19 are 1-3 bits.
        expected = [4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 24, 32, 48, 64, 1, 2, 3]
        self.assertEqual(list(INTEGER_BITS), expected)
        for pfc, bits in enumerate(expected):
            self.assertEqual(field(3, pfc).bits, bits)
            top = (1 << bits) - 1
            self.assertEqual(field(3, pfc).unpack(field(3, pfc).pack(top)), top)

    def test_unsigned_vectors(self):
        self.assertEqual(field(3, 4).pack(0xAB), b"\xab")
        self.assertEqual(field(3, 12).pack(0x1234), b"\x12\x34")
        self.assertEqual(field(3, 13).pack(0x123456), b"\x12\x34\x56")
        self.assertEqual(field(3, 14).pack(0xDEADBEEF), bytes.fromhex("deadbeef"))
        self.assertEqual(field(3, 15).pack(1), bytes.fromhex("000000000001"))
        self.assertEqual(field(3, 16).pack(2**64 - 1), b"\xff" * 8)
        self.assertEqual(field(3, 0).pack(0xA), b"\xa0")
        self.assertEqual(field(3, 17).pack(1), b"\x80")

    def test_unsigned_range(self):
        for bad in (-1, 256, 1.0, "1", None):
            with self.assertRaises(FieldValueError):
                field(3, 4).pack(bad)

    def test_signed_widths_and_vectors(self):
        for pfc in range(17):
            bits = INTEGER_BITS[pfc]
            f = field(4, pfc)
            self.assertEqual(f.bits, bits)
            for v in (-(1 << (bits - 1)), -1, 0, 1, (1 << (bits - 1)) - 1):
                self.assertEqual(f.unpack(f.pack(v)), v)
        self.assertEqual(field(4, 0).pack(-1), b"\xf0")
        self.assertEqual(field(4, 4).pack(-128), b"\x80")
        self.assertEqual(field(4, 12).pack(-2), b"\xff\xfe")
        self.assertEqual(field(4, 13).pack(-2), b"\xff\xff\xfe")
        self.assertEqual(field(4, 15).unpack(b"\x80\x00\x00\x00\x00\x00"), -(1 << 47))
        self.assertEqual(field(4, 5).unpack(b"\xff\x80"), -1)  # 9 bits

    def test_signed_range(self):
        with self.assertRaises(FieldValueError):
            field(4, 4).pack(128)
        with self.assertRaises(FieldValueError):
            field(4, 0).pack(-9)


class TestReal(unittest.TestCase):
    def test_ieee(self):
        self.assertEqual(field(5, 1).pack(1.0), bytes.fromhex("3f800000"))
        self.assertEqual(field(5, 1).pack(-2.5), bytes.fromhex("c0200000"))
        self.assertEqual(field(5, 2).pack(1.0), bytes.fromhex("3ff0000000000000"))
        self.assertEqual(field(5, 2).unpack(bytes.fromhex("400921fb54442d18")), 3.141592653589793)
        self.assertEqual(
            field(5, 1).unpack(bytes.fromhex("40490fdb")),
            field(5, 1).unpack(field(5, 1).pack(3.1415927)),
        )

    def test_ieee_errors(self):
        with self.assertRaises(FieldValueError):
            field(5, 1).pack(1e39)
        with self.assertRaises(FieldValueError):
            field(5, 2).pack("x")

    def test_mil_std_1750a_simple(self):
        # MIL-STD-1750A table of 32-bit floating point examples (mantissa, exponent)
        f = field(5, 3)
        vectors = (
            (0.5 * 2.0**127, "4000007f"),
            (0.625 * 2.0**4, "50000004"),
            (1.0, "40000001"),
            (0.5, "40000000"),
            (0.25, "400000ff"),
            (0.5 * 2.0**-128, "40000080"),
            (0.0, "00000000"),
            (-1.0, "80000000"),
            (-0.5, "800000ff"),
            (-(2.0**127), "8000007f"),
        )
        for value, hexa in vectors:
            self.assertEqual(f.pack(value).hex(), hexa)
            self.assertEqual(f.unpack(bytes.fromhex(hexa)), value)
        self.assertEqual(f.unpack(bytes.fromhex("7fffff7f")), (1 - 2.0**-23) * 2.0**127)
        self.assertEqual(f.unpack(bytes.fromhex("9fffff04")), -0.7500001192092896 * 16)

    def test_mil_std_1750a_extended(self):
        f = field(5, 4)
        self.assertEqual(f.bits, 48)
        for value, hexa in (
            (0.5 * 2.0**127, "4000007f0000"),
            (0.5, "400000000000"),
            (-1.0, "800000000000"),
            (0.0, "000000000000"),
        ):
            self.assertEqual(f.pack(value).hex(), hexa)
            self.assertEqual(f.unpack(bytes.fromhex(hexa)), value)
        self.assertEqual(f.unpack(bytes.fromhex("7fffff7fffff")), (1 - 2.0**-39) * 2.0**127)
        self.assertEqual(f.unpack(bytes.fromhex("9fffff04ffff")), (-0.75 - 2.0**-39) * 16)

    def test_mil_std_1750a_range(self):
        with self.assertRaises(FieldValueError):
            field(5, 3).pack(2.0**128)
        with self.assertRaises(FieldValueError):
            field(5, 3).pack(float("inf"))
        self.assertEqual(field(5, 3).pack(2.0**-200), b"\x00" * 4)  # underflow flushes to 0

    def test_mil_std_1750a_precision(self):
        f = field(5, 4)
        for v in (3.14159, -123.456, 1e-30, 6.02e23):
            self.assertAlmostEqual(f.unpack(f.pack(v)) / v, 1.0, places=9)


class TestOffsets(unittest.TestCase):
    def test_fields_share_octets(self):
        e = Encoder()
        field(1, 0).write(e, True)
        field(2, 3).write(e, 2)
        field(4, 0).write(e, -3)
        field(3, 12).write(e, 0xBEEF)
        self.assertEqual(e.bit_length, 24)
        d = Decoder(e.getvalue())
        self.assertIs(field(1, 0).read(d), True)
        self.assertEqual(field(2, 3).read(d), 2)
        self.assertEqual(field(4, 0).read(d), -3)
        self.assertEqual(field(3, 12).read(d), 0xBEEF)

    def test_real_at_odd_offset(self):
        e = Encoder()
        field(2, 5).write(e, 3)
        field(5, 2).write(e, -0.1)
        field(5, 1).write(e, 0.5)
        d = Decoder(e.getvalue())
        self.assertEqual(field(2, 5).read(d), 3)
        self.assertEqual(field(5, 2).read(d), -0.1)
        self.assertEqual(field(5, 1).read(d), 0.5)

    def test_short_buffer(self):
        with self.assertRaises(BitsTooShortError):
            field(3, 14).unpack(b"\x00\x00\x00")
        with self.assertRaises(BitsTooShortError):
            field(5, 4).unpack(b"\x00" * 5)
