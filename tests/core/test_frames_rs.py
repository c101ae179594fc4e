"""Reed-Solomon of CCSDS 131.0-B: dual basis, libfec vectors, errors, erasures, interleaving."""

import unittest

from obsw.frames import rs
from obsw.frames.errors import FrameLengthError, RsUncorrectableError

# libfec's ccsds_tab.c (Taltab, conventional -> dual basis), its first sixteen entries.
TALTAB_0_15 = bytes.fromhex("007bafd499e2364dfa81552e6318ccb7")
# Check symbols computed by libfec (encode_rs_ccsds; the general codec with first root 120,
# step 11 for E=8) for data 00 01 02 ...: an independent implementation's output.
CHECK_E16_223 = bytes.fromhex("4ffb92dd557ec67f27fb8982cf58f8fd028ad117fcef6b2793d0418826578651")
CHECK_E8_239 = bytes.fromhex("9755133f2714a3fbe0101e8f0e0ac1d2")
CHECK_E8_100 = bytes.fromhex("dcd78333e6e1fa685ad08f5d434a8285")


class Lcg:
    """The same pseudo-random numbers on every interpreter (MicroPython's random differs)."""

    def __init__(self, seed):
        self.x = seed

    def next(self, n):
        self.x = (self.x * 1103515245 + 12345) & 0x7FFFFFFF
        return (self.x >> 8) % n

    def data(self, n):
        return bytes(self.next(256) for _ in range(n))

    def positions(self, count, n):
        out = []
        while len(out) < count:
            p = self.next(n)
            if p not in out:
                out.append(p)
        return out


def corrupt(block, positions, rnd):
    bad = bytearray(block)
    for p in positions:
        bad[p] ^= 1 + rnd.next(255)
    return bytes(bad)


class TestDualBasis(unittest.TestCase):
    def test_first_entries_match_ccsds_tab(self):
        self.assertEqual(rs.to_dual(bytes(range(16))), TALTAB_0_15)

    def test_round_trip_all_octets(self):
        every = bytes(range(256))
        self.assertEqual(rs.to_conventional(rs.to_dual(every)), every)
        self.assertEqual(len(set(rs.to_dual(every))), 256)

    def test_generator_degree_and_roots(self):
        for e in (16, 8):
            g = rs.generator(e)
            self.assertEqual(len(g), 2 * e + 1)
            self.assertEqual(g[0], 1)


class TestVectors(unittest.TestCase):
    def test_e16_full_length(self):
        code = rs.ReedSolomon(16)
        block = code.encode(bytes(range(223)))
        self.assertEqual(block[223:], CHECK_E16_223)
        self.assertEqual(block[:223], bytes(range(223)))

    def test_e8_full_and_shortened(self):
        self.assertEqual(rs.ReedSolomon(8).encode(bytes(range(239)))[239:], CHECK_E8_239)
        self.assertEqual(rs.ReedSolomon(8, 1, 100).encode(bytes(range(100)))[100:], CHECK_E8_100)

    def test_interleaved_codewords_are_the_single_ones(self):
        rnd = Lcg(1)
        for depth in rs.DEPTHS:
            code = rs.ReedSolomon(16, depth, 10 * depth)
            frame = rnd.data(10 * depth)
            block = code.encode(frame)
            one = rs.ReedSolomon(16, 1, 10)
            for w in range(depth):
                word = bytes(block[t] for t in range(w, len(block), depth))
                self.assertEqual(one.encode(word[:10]), word)


class TestDecode(unittest.TestCase):
    def test_clean_block(self):
        code = rs.ReedSolomon(16, 2)
        frame = Lcg(2).data(446)
        self.assertEqual(code.decode(code.encode(frame)), (frame, [0, 0]))

    def test_up_to_e_errors_each_codeword(self):
        rnd = Lcg(3)
        for e in (16, 8):
            for depth in (1, 3, 8):
                for per_word in range(e + 1):
                    code = rs.ReedSolomon(e, depth, 40 * depth)
                    frame = rnd.data(code.length)
                    block = code.encode(frame)
                    pos = []
                    for w in range(depth):
                        for s in rnd.positions(per_word, 40 + 2 * e):
                            pos.append(s * depth + w)
                    got, fixed = code.decode(corrupt(block, pos, rnd))
                    self.assertEqual(got, frame)
                    self.assertEqual(fixed, [per_word] * depth)

    def test_errors_and_erasures_within_2e(self):
        rnd = Lcg(4)
        for e in (16, 8):
            code = rs.ReedSolomon(e, 1, 223 if e == 16 else 239)
            for errors in range(e + 1):
                erasures = 2 * e - 2 * errors
                frame = rnd.data(code.length)
                block = code.encode(frame)
                pos = rnd.positions(errors + erasures, code.block_length)
                bad = corrupt(block, pos, rnd)
                got, fixed = code.decode(bad, pos[errors:])
                self.assertEqual(got, frame)
                self.assertEqual(fixed, [errors + erasures])

    def test_erased_symbols_that_are_right(self):
        code = rs.ReedSolomon(8)
        frame = Lcg(5).data(239)
        block = code.encode(frame)
        self.assertEqual(code.decode(block, [0, 5, 254]), (frame, [0]))
        bad = corrupt(block, [7], Lcg(6))
        self.assertEqual(code.decode(bad, [0, 5, 7]), (frame, [1]))

    def test_one_error_too_many(self):
        rnd = Lcg(7)
        for e in (16, 8):
            code = rs.ReedSolomon(e, 2, 2 * 60)
            frame = rnd.data(code.length)
            block = code.encode(frame)
            pos = [2 * s + 1 for s in rnd.positions(e + 1, 60 + 2 * e)]
            bad = corrupt(block, pos, rnd)
            with self.assertRaises(RsUncorrectableError) as cm:
                code.decode(bad)
            self.assertEqual(cm.exception.codewords, [1])
            self.assertEqual(cm.exception.corrected, [0, -1])
            self.assertEqual(len(cm.exception.data), code.length)

    def test_too_many_erasures(self):
        code = rs.ReedSolomon(8, 1, 50)
        block = code.encode(bytes(50))
        bad = corrupt(block, [0], Lcg(8))
        with self.assertRaises(RsUncorrectableError):
            code.decode(bad, list(range(17)))
        self.assertEqual(code.decode(bad, list(range(16)))[0], bytes(50))

    def test_fast_and_pure_paths_agree(self):
        rnd = Lcg(9)
        for depth in rs.DEPTHS:
            frame = rnd.data(30 * depth)
            fast = rs.ReedSolomon(16, depth, 30 * depth, fast=rs.bytes_ops())
            slow = rs.ReedSolomon(16, depth, 30 * depth, fast=False)
            block = slow.encode(frame)
            self.assertEqual(fast.encode(frame), block)
            bad = corrupt(block, rnd.positions(5, len(block)), rnd)
            self.assertEqual(fast.decode(bad), slow.decode(bad))


class TestBoundaries(unittest.TestCase):
    def test_lengths(self):
        for depth in rs.DEPTHS:
            self.assertEqual(rs.ReedSolomon(16, depth).length, 223 * depth)
            self.assertEqual(rs.ReedSolomon(8, depth, depth).fill, 238)
            with self.assertRaises(FrameLengthError):
                rs.ReedSolomon(16, depth, 223 * depth + depth)
            if depth > 1:
                with self.assertRaises(FrameLengthError):
                    rs.ReedSolomon(16, depth, 10 * depth + 1)
        with self.assertRaises(FrameLengthError):
            rs.ReedSolomon(8, 1, 0)
        self.assertEqual(rs.ReedSolomon(16, 5, 1115).block_length, 1115 + 160)

    def test_parameters(self):
        for bad in ((12, 1), (16, 6), (16, 0), (8, 16)):
            with self.assertRaises(ValueError):
                rs.ReedSolomon(bad[0], bad[1])

    def test_block_length_checked(self):
        code = rs.ReedSolomon(16, 1, 100)
        with self.assertRaises(FrameLengthError):
            code.decode(bytes(131))
        with self.assertRaises(FrameLengthError):
            code.encode(bytes(99))
        with self.assertRaises(ValueError):
            code.decode(bytes(132), [132])


if __name__ == "__main__":
    unittest.main()
