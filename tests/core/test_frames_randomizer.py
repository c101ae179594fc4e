"""CCSDS pseudo-randomizers checked against their definitions in 131.0-B and 231.0-B."""

import unittest

from obsw.frames import randomizer


def _lfsr_bits(terms, count):
    # The sequence obeys the recurrence of h(x): s[n+8] is the XOR of s[n+k] for every term
    # x^k of h(x) below x^8; the first eight bits are ones (register preset to all ones).
    s = [1] * 8
    while len(s) < count:
        n = len(s) - 8
        b = 0
        for k in terms:
            b ^= s[n + k]
        s.append(b)
    return s[:count]


def _bytes_of(bits):
    out = bytearray(len(bits) // 8)
    for i, b in enumerate(bits[: len(out) * 8]):
        out[i >> 3] |= b << (7 - (i & 7))
    return bytes(out)


class TestSequences(unittest.TestCase):
    def test_tm_first_bytes(self):
        # 131.0-B: the sequence begins 1111 1111 0100 1000 0000 1110 1100 0000 1001 1010...
        self.assertEqual(randomizer.tm_sequence()[:5], b"\xff\x48\x0e\xc0\x9a")

    def test_tc_first_bytes(self):
        # 231.0-B: the sequence begins 1111 1111 0011 1001 1001 1110 0101 1010 0110 1000...
        self.assertEqual(randomizer.tc_sequence()[:5], b"\xff\x39\x9e\x5a\x68")

    def test_tm_whole_period_from_polynomial(self):
        # h(x) = x^8 + x^7 + x^5 + x^3 + 1
        ref = _bytes_of(_lfsr_bits((0, 3, 5, 7), 255 * 8))
        self.assertEqual(randomizer.tm_sequence(), ref)

    def test_tc_whole_period_from_polynomial(self):
        # h(x) = x^8 + x^6 + x^4 + x^3 + x^2 + x + 1.
        ref = _bytes_of(_lfsr_bits((0, 1, 2, 3, 4, 6), 255 * 8))
        self.assertEqual(randomizer.tc_sequence(), ref)

    def test_period_is_255_bits(self):
        bits = _lfsr_bits((0, 3, 5, 7), 600)
        self.assertEqual(bits[:345], bits[255:600])

    def test_randomize_is_its_own_inverse(self):
        data = bytes(range(256)) * 3
        for f in (randomizer.randomize_tm, randomizer.randomize_tc):
            r = f(data)
            self.assertNotEqual(r, data)
            self.assertEqual(f(r), data)

    def test_repeats_after_255_bytes(self):
        zeros = bytes(600)
        r = randomizer.randomize_tm(zeros)
        self.assertEqual(r[:255], randomizer.tm_sequence())
        self.assertEqual(r[255:510], randomizer.tm_sequence())
        self.assertEqual(r[510:], randomizer.tm_sequence()[:90])


if __name__ == "__main__":
    unittest.main()
