"""KISS framing: escapes, commands and ports, garbage between frames, length limits."""

import unittest

from obsw.frames import kiss


class KissTest(unittest.TestCase):
    def test_escapes_both_special_octets(self):
        self.assertEqual(
            kiss.encode(b"\x01\xc0\x02\xdb\x03"), b"\xc0\x00\x01\xdb\xdc\x02\xdb\xdd\x03\xc0"
        )

    def test_round_trip_every_octet(self):
        data = bytes(range(256)) * 2
        d = kiss.KissDecoder()
        self.assertEqual(d.feed(kiss.encode(data)), [data])
        self.assertEqual(d.frames, 1)

    def test_frames_split_anywhere_and_back_to_back(self):
        frames = [b"\xc0", b"\xdb\xdc", bytes(range(40)), b"x"]
        stream = b"".join(kiss.encode(f) for f in frames)
        for step in (1, 2, 3, 7, len(stream)):
            d = kiss.KissDecoder()
            got = []
            for i in range(0, len(stream), step):
                got += d.feed(stream[i : i + step])
            self.assertEqual(got, frames)

    def test_garbage_before_the_first_fend_and_repeated_fends(self):
        d = kiss.KissDecoder()
        self.assertEqual(d.feed(b"noise\xc0\xc0\xc0\x00ab\xc0\xc0"), [b"ab"])
        self.assertEqual(d.skipped, 0)

    def test_other_commands_and_empty_frames_skipped(self):
        d = kiss.KissDecoder()
        got = d.feed(b"\xc0\x01\x32\xc0" + b"\xc0\x00\xc0" + kiss.encode(b"ok"))
        self.assertEqual(got, [b"ok"])
        self.assertEqual(d.skipped, 2)

    def test_port_filter(self):
        d = kiss.KissDecoder(port=1)
        got = d.feed(kiss.encode(b"p0") + kiss.encode(b"p1", port=1))
        self.assertEqual(got, [b"p1"])
        self.assertEqual(kiss.encode(b"", port=2)[1], 0x20)

    def test_port_12_command_octet_escaped(self):
        self.assertEqual(kiss.encode(b"a", port=12), b"\xc0\xdb\xdca\xc0")
        self.assertEqual(kiss.KissDecoder(port=12).feed(kiss.encode(b"a", port=12)), [b"a"])

    def test_bad_escape_counted_octet_kept(self):
        d = kiss.KissDecoder()
        self.assertEqual(d.feed(b"\xc0\x00a\xdbzb\xc0"), [b"azb"])
        self.assertEqual(d.bad_escapes, 1)

    def test_length_limit_edges(self):
        d = kiss.KissDecoder(max_length=4)
        self.assertEqual(d.feed(kiss.encode(b"1234")), [b"1234"])
        self.assertEqual(d.feed(kiss.encode(b"12345")), [])
        self.assertEqual(d.feed(kiss.encode(b"123")), [b"123"])
        self.assertEqual(d.skipped, 1)
        self.assertEqual(d.feed(kiss.encode(b"\xc0" * 4)), [b"\xc0" * 4])  # escapes count once


if __name__ == "__main__":
    unittest.main()
