"""CLTU encoding and decoding (CCSDS 231.0-B): start and tail sequences, fill, correction."""

import unittest

from obsw.frames import bch, cltu
from obsw.frames.errors import CltuError
from obsw.frames.randomizer import randomize_tc


class TestEncode(unittest.TestCase):
    def test_layout_with_fill(self):
        frame = bytes(range(10))
        c = cltu.encode(frame)
        self.assertEqual(c[:2], b"\xeb\x90")
        self.assertEqual(c[-8:], b"\xc5\xc5\xc5\xc5\xc5\xc5\xc5\x79")
        self.assertEqual(len(c), 2 + 2 * 8 + 8)
        self.assertEqual(c[2:9], frame[:7])
        self.assertEqual(c[10:13], frame[7:])
        self.assertEqual(c[13:17], b"\x55\x55\x55\x55")  # fill: alternating 0 and 1 bits
        self.assertEqual(c[9], bch.parity(frame[:7]))
        self.assertEqual(c[17], bch.parity(c[10:17]))

    def test_known_codeblocks(self):
        # An all-zero 7-byte frame: one codeblock, parity 0xFE (complemented zero remainder).
        self.assertEqual(
            cltu.encode(bytes(7)),
            b"\xeb\x90" + bytes(7) + b"\xfe" + b"\xc5\xc5\xc5\xc5\xc5\xc5\xc5\x79",
        )

    def test_exact_multiple_has_no_fill(self):
        c = cltu.encode(bytes(14))
        self.assertEqual(len(c), 2 + 16 + 8)

    def test_randomized(self):
        frame = bytes(20)
        c = cltu.encode(frame, randomize=True)
        self.assertEqual(c[2:9], randomize_tc(frame)[:7])
        data, fixed = cltu.decode(c, derandomize=True)
        self.assertEqual(data[:20], frame)
        self.assertEqual(fixed, 0)


class TestDecode(unittest.TestCase):
    def test_round_trip(self):
        for n in (1, 6, 7, 8, 13, 14, 100, 1024):
            frame = bytes((i * 7 + n) & 0xFF for i in range(n))
            data, fixed = cltu.decode(cltu.encode(frame))
            self.assertEqual(data[:n], frame)
            self.assertEqual(len(data), ((n + 6) // 7) * 7)
            self.assertEqual(fixed, 0)

    def test_one_error_per_codeblock_is_corrected(self):
        frame = bytes(range(70))
        c = bytearray(cltu.encode(frame))
        for k in range(10):
            c[2 + 8 * k + (k % 8)] ^= 1 << (k % 8)
        data, fixed = cltu.decode(bytes(c))
        self.assertEqual(data[:70], frame)
        self.assertEqual(fixed, 10)

    def test_double_error_is_uncorrectable(self):
        c = bytearray(cltu.encode(bytes(20)))
        c[10] ^= 0x03
        with self.assertRaises(CltuError) as ctx:
            cltu.decode(bytes(c))
        self.assertEqual(ctx.exception.block, 1)

    def test_bad_framing(self):
        good = cltu.encode(bytes(7))
        for bad in (b"", good[:10], b"\xeb\x91" + good[2:], good[:-1] + b"\x78", good + b"\x00"):
            with self.assertRaises(CltuError):
                cltu.decode(bad)


class TestStream(unittest.TestCase):
    def test_noise_between_cltus_and_split_feeding(self):
        frames = [bytes([k]) * (5 + 9 * k) for k in range(4)]
        stream = b"\x00\xeb\x12" + b"".join(
            cltu.encode(f) + b"\x33" * k for k, f in enumerate(frames)
        )
        dec = cltu.CltuDecoder()
        out = []
        for i in range(0, len(stream), 5):
            out.extend(dec.feed(stream[i : i + 5]))
        self.assertEqual([d[: len(f)] for d, f in zip(out, frames)], frames)
        self.assertEqual(dec.cltus, 4)
        self.assertEqual(dec.aborted, 0)
        self.assertEqual(dec.skipped, 3 + 0 + 1 + 2 + 3)

    def test_uncorrectable_block_aborts_and_decoder_recovers(self):
        bad = bytearray(cltu.encode(bytes(30)))
        bad[12] ^= 0x81
        good = cltu.encode(b"\x42" * 9)
        dec = cltu.CltuDecoder()
        out = dec.feed(bytes(bad) + good)
        self.assertEqual(len(out), 1)
        self.assertEqual(out[0][:9], b"\x42" * 9)
        self.assertEqual(dec.aborted, 1)

    def test_corrected_bits_are_counted(self):
        c = bytearray(cltu.encode(bytes(21)))
        c[3] ^= 0x10
        c[20] ^= 0x01
        dec = cltu.CltuDecoder()
        out = dec.feed(bytes(c))
        self.assertEqual(out[0], bytes(21))
        self.assertEqual(dec.corrected, 2)

    def test_overlong_cltu_is_aborted(self):
        dec = cltu.CltuDecoder(max_blocks=2)
        self.assertEqual(dec.feed(cltu.encode(bytes(30))), [])
        self.assertEqual(dec.aborted, 1)


class TestCltuBoundaries(unittest.TestCase):
    def test_the_shortest_cltu_exactly(self):
        # start sequence 2 + one codeblock 8 + tail sequence 8 = 18 octets at least
        shortest = cltu.encode(b"\x01\x02\x03")
        self.assertEqual(len(shortest), 18)
        self.assertEqual(cltu.decode(shortest)[0][:3], b"\x01\x02\x03")
        with self.assertRaises(CltuError):
            cltu.decode(shortest[:17])

    def test_a_start_then_a_tail_is_an_aborted_cltu(self):
        d = cltu.CltuDecoder()
        self.assertEqual(d.feed(cltu.START_SEQUENCE + cltu.TAIL_SEQUENCE), [])
        self.assertEqual((d.cltus, d.aborted), (0, 1))

    def test_a_start_sequence_split_across_feeds(self):
        # the stream's last octet may be the first of a start sequence: it waits for the next
        whole = cltu.encode(b"\x0a\x0b")
        d = cltu.CltuDecoder()
        self.assertEqual(d.feed(b"\x00\x00" + whole[:1]), [])
        self.assertEqual(d.skipped, 2)
        self.assertEqual([x[:2] for x in d.feed(whole[1:])], [b"\x0a\x0b"])
        self.assertEqual((d.skipped, d.cltus), (2, 1))


if __name__ == "__main__":
    unittest.main()
