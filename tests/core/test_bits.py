"""Progressive bit encoder/decoder: widths, offsets, alignment and short-buffer errors."""

import unittest

from obsw.bits import BitsTooShortError, BitsValueError, Decoder, Encoder


class TestEncoder(unittest.TestCase):
    def test_bits_msb_first(self):
        e = Encoder()
        e.write(1, 1)
        e.write(0, 2)
        e.write(0b10110, 5)
        self.assertEqual(e.getvalue(), bytes([0b10010110]))
        self.assertEqual(e.bit_length, 8)

    def test_space_packet_header_fields(self):
        # CCSDS primary header: version 0, TC, sec header, APID 0x73, unsegmented, count 25
        e = Encoder()
        for value, width in ((0, 3), (1, 1), (1, 1), (0x73, 11), (3, 2), (25, 14), (4, 16)):
            e.write(value, width)
        self.assertEqual(e.getvalue(), bytes.fromhex("1873c0190004"))

    def test_aligned_fast_path_and_partial_octet(self):
        e = Encoder()
        e.write(0xABCD, 16)
        self.assertTrue(e.aligned)
        e.write(0x5, 4)
        self.assertFalse(e.aligned)
        self.assertEqual(e.bit_length, 20)
        self.assertEqual(e.getvalue(), bytes.fromhex("abcd50"))
        self.assertEqual(e.pad_to_byte(), 4)
        self.assertEqual(e.pad_to_byte(), 0)
        self.assertEqual(e.getvalue(), bytes.fromhex("abcd50"))

    def test_write_bytes_at_odd_offset(self):
        e = Encoder()
        e.write(1, 1)
        e.write_bytes(b"\xff\x00")
        e.write(0, 7)
        self.assertEqual(e.getvalue(), bytes([0xFF, 0x80, 0x00]))

    def test_write_struct_aligned_and_not(self):
        e = Encoder()
        e.write_struct(">HB", 0x0102, 3)
        e.write(0, 4)
        e.write_struct(">B", 0xAB)
        e.write(0xC, 4)
        self.assertEqual(e.getvalue(), bytes.fromhex("0102030abc"))

    def test_wide_values(self):
        e = Encoder()
        e.write(3, 3)
        e.write((1 << 100) - 1, 100)
        d = Decoder(e.getvalue())
        self.assertEqual(d.read(3), 3)
        self.assertEqual(d.read(100), (1 << 100) - 1)

    def test_zero_width(self):
        e = Encoder()
        e.write(0, 0)
        self.assertEqual(e.getvalue(), b"")

    def test_value_out_of_range(self):
        e = Encoder()
        with self.assertRaises(BitsValueError) as cm:
            e.write(8, 3)
        self.assertEqual(cm.exception.value, 8)
        self.assertEqual(cm.exception.nbits, 3)
        with self.assertRaises(ValueError):
            e.write(-1, 8)


class TestDecoder(unittest.TestCase):
    def test_reads_at_bit_offsets(self):
        d = Decoder(bytes.fromhex("1873c0190004"))
        self.assertEqual([d.read(w) for w in (3, 1, 1, 11, 2, 14, 16)], [0, 1, 1, 0x73, 3, 25, 4])
        self.assertEqual(d.bits_left, 0)

    def test_initial_bit_offset(self):
        d = Decoder(bytes([0b00011111, 0xF0]), bit_offset=3)
        self.assertEqual(d.bit_position, 3)
        self.assertEqual(d.read(9), 0x1FF)

    def test_read_bytes_unaligned(self):
        d = Decoder(bytes([0x0F, 0xF0, 0x0F]))
        d.skip(4)
        self.assertEqual(d.read_bytes(2), b"\xff\x00")
        self.assertEqual(d.read(4), 0xF)

    def test_read_struct(self):
        d = Decoder(bytes.fromhex("01020304") + bytes([0x0A, 0xBC]))
        self.assertEqual(d.read_struct(">HH", 4), (0x0102, 0x0304))
        d.skip(4)
        self.assertEqual(d.read_struct(">B", 1), (0xAB,))
        self.assertEqual(d.bits_left, 4)

    def test_align_and_rest(self):
        d = Decoder(b"\xff\x01\x02")
        d.read(3)
        self.assertEqual(d.align(), 5)
        self.assertEqual(d.align(), 0)
        self.assertEqual(d.rest(), b"\x01\x02")

    def test_memoryview_and_bytearray(self):
        for buf in (bytearray(b"\x12\x34"), memoryview(b"\x12\x34")):
            d = Decoder(buf)
            self.assertEqual(d.read(4), 1)
            self.assertEqual(d.read(8), 0x23)
            self.assertEqual(d.read_bytes(0), b"")

    def test_too_short_carries_bits(self):
        d = Decoder(b"\x00\x00")
        d.read(5)
        with self.assertRaises(BitsTooShortError) as cm:
            d.read(12)
        self.assertEqual(cm.exception.needed, 12)
        self.assertEqual(cm.exception.got, 11)
        self.assertEqual(d.bit_position, 5)  # a failed read consumes nothing
        with self.assertRaises(BitsTooShortError):
            d.read_bytes(2)
        with self.assertRaises(BitsTooShortError):
            d.read_struct(">H", 2)
        with self.assertRaises(BitsTooShortError):
            d.skip(12)
        with self.assertRaises(BitsTooShortError):
            Decoder(b"\x00", bit_offset=9)

    def test_round_trip_mixed_widths(self):
        widths = [1, 7, 3, 13, 8, 16, 5, 24, 2, 32, 11, 64]
        values = [(0x5A5A5A5A5A5A5A5A5A >> i) & ((1 << w) - 1) for i, w in enumerate(widths)]
        e = Encoder()
        for v, w in zip(values, widths):
            e.write(v, w)
        d = Decoder(e.getvalue())
        self.assertEqual([d.read(w) for w in widths], values)
        self.assertEqual(d.bits_left, -sum(widths) % 8)
