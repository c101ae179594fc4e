"""BCH(63,56) codeblocks (CCSDS 231.0-B): parity from the generator polynomial, correction."""

import unittest

from obsw.frames import bch

G = 0b11000101  # x^7 + x^6 + x^2 + 1


def _reference_parity(info):
    # Long division of i(x) * x^7 by g(x), bit by bit, straight from the definition.
    reg = 0
    for byte in info:
        for k in range(7, -1, -1):
            reg = (reg << 1) | ((byte >> k) & 1)
            if reg & 0x80:
                reg ^= G
    for _ in range(7):
        reg <<= 1
        if reg & 0x80:
            reg ^= G
    return ((~reg) & 0x7F) << 1  # complemented parity bits, filler bit 0


class TestParity(unittest.TestCase):
    def test_all_zero_information(self):
        # Remainder 0, complemented to seven ones, filler 0.
        self.assertEqual(bch.parity(bytes(7)), 0xFE)

    def test_lowest_information_bit(self):
        # x^7 mod g(x) = x^6 + x^2 + 1 -> 1000101, complemented 0111010, filler 0.
        self.assertEqual(bch.parity(b"\x00\x00\x00\x00\x00\x00\x01"), 0x74)

    def test_matches_polynomial_division(self):
        seed = 12345
        for _ in range(300):
            info = bytearray(7)
            for i in range(7):
                seed = (seed * 1103515245 + 12345) & 0x7FFFFFFF
                info[i] = seed >> 16 & 0xFF
            self.assertEqual(bch.parity(info), _reference_parity(info))
        self.assertEqual(bch.parity(b"\xff" * 7), _reference_parity(b"\xff" * 7))

    def test_encode_block(self):
        info = b"\x12\x34\x56\x78\x9a\xbc\xde"
        block = bch.encode_block(info)
        self.assertEqual(block[:7], info)
        self.assertEqual(block[7], _reference_parity(info))
        with self.assertRaises(ValueError):
            bch.encode_block(b"\x00" * 6)


class TestCorrection(unittest.TestCase):
    def _blocks(self):
        return (bch.encode_block(bytes(7)), bch.encode_block(b"\x01\x23\x45\x67\x89\xab\xcd"))

    def test_clean_block(self):
        for block in self._blocks():
            buf = bytearray(block)
            self.assertEqual(bch.correct(buf), 0)
            self.assertEqual(bytes(buf), block)

    def test_every_single_bit_error_is_corrected(self):
        for block in self._blocks():
            for bit in range(63):
                buf = bytearray(block)
                buf[bit >> 3] ^= 0x80 >> (bit & 7)
                self.assertEqual(bch.correct(buf), 1)
                self.assertEqual(bytes(buf), block)

    def test_filler_bit_is_not_checked(self):
        block = self._blocks()[1]
        buf = bytearray(block)
        buf[7] ^= 1
        self.assertEqual(bch.correct(buf), 0)

    def test_every_double_error_is_detected(self):
        block = self._blocks()[1]
        for a in range(63):
            for b in range(a + 1, 63):
                buf = bytearray(block)
                buf[a >> 3] ^= 0x80 >> (a & 7)
                buf[b >> 3] ^= 0x80 >> (b & 7)
                self.assertEqual(bch.correct(buf), -1)

    def test_offset_into_buffer(self):
        block = self._blocks()[1]
        buf = bytearray(b"\xaa\xbb" + block)
        buf[4] ^= 0x08
        self.assertEqual(bch.correct(buf, 2), 1)
        self.assertEqual(bytes(buf[2:]), block)


if __name__ == "__main__":
    unittest.main()
