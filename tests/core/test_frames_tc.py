"""TC transfer frames (CCSDS 232.0-B): header bits, FECF, control commands, segments, CLCW."""

import unittest

from obsw.crc import crc16_ccitt
from obsw.frames import tc
from obsw.frames.clcw import Clcw
from obsw.frames.errors import (
    ControlCommandError,
    FecfError,
    FrameError,
    FrameHeaderError,
    FrameLengthError,
    FrameTooShortError,
)


class TestTcFrame(unittest.TestCase):
    def test_header_layout(self):
        f = tc.TcFrame(0x2AB, 0x15, b"\x01\x02\x03", seq=0x7E, bypass=True)
        raw = f.pack()
        # version 00, bypass 1, control 0, spare 00, SCID 10 bits, VCID 6, length-1 10, N(S) 8
        self.assertEqual(raw[:5], bytes((0x22, 0xAB, 0x15 << 2, 9, 0x7E)))
        self.assertEqual(len(raw), 10)
        self.assertEqual(raw[5:8], b"\x01\x02\x03")
        self.assertEqual((raw[8] << 8) | raw[9], crc16_ccitt(raw[:8]))
        self.assertEqual(crc16_ccitt(raw), 0)  # appending the FECF gives a zero residue

    def test_types(self):
        self.assertEqual(tc.TcFrame(1, 0, b"x").type_name, "AD")
        self.assertEqual(tc.TcFrame(1, 0, b"x", bypass=True).type_name, "BD")
        self.assertEqual(tc.TcFrame(1, 0, b"x", bypass=True, control=True).type_name, "BC")
        self.assertEqual(tc.TcFrame(1, 0, b"x", control=True).frame_type, tc.TYPE_AC)

    def test_round_trip(self):
        f = tc.TcFrame(1023, 63, bytes(range(200)), 255, True, True)
        g = tc.TcFrame.unpack(f.pack())
        self.assertEqual((g.scid, g.vcid, g.seq, g.bypass, g.control), (1023, 63, 255, True, True))
        self.assertEqual(g.data, f.data)
        self.assertEqual(g, f)
        h = tc.TcFrame.unpack(tc.TcFrame(3, 4, b"abc", fecf=False).pack(), fecf=False)
        self.assertEqual(h.data, b"abc")

    def test_trailing_fill(self):
        raw = tc.TcFrame(5, 1, b"hello").pack()
        self.assertEqual(tc.TcFrame.unpack(raw + b"\x55\x55", trailing=True).data, b"hello")
        with self.assertRaises(FrameLengthError):
            tc.TcFrame.unpack(raw + b"\x55")

    def test_errors(self):
        raw = bytearray(tc.TcFrame(5, 1, b"hello").pack())
        with self.assertRaises(FrameTooShortError):
            tc.TcFrame.unpack(raw[:4])
        with self.assertRaises(FrameTooShortError):
            tc.TcFrame.unpack(raw[:-1])
        bad = bytearray(raw)
        bad[6] ^= 1
        with self.assertRaises(FecfError):
            tc.TcFrame.unpack(bytes(bad))
        bad = bytearray(raw)
        bad[0] |= 0x40
        with self.assertRaises(FrameHeaderError):
            tc.TcFrame.unpack(bytes(bad))
        with self.assertRaises(FrameLengthError):
            tc.TcFrame(1, 0, bytes(1018)).pack()
        self.assertEqual(len(tc.TcFrame(1, 0, bytes(1017)).pack()), 1024)

    def test_errors_are_value_errors(self):
        self.assertTrue(issubclass(FecfError, FrameError))
        self.assertTrue(issubclass(FrameError, ValueError))


class TestControlCommands(unittest.TestCase):
    def test_unlock_and_set_vr(self):
        self.assertEqual(tc.UNLOCK, b"\x00")
        self.assertEqual(tc.set_vr_command(200), b"\x82\x00\xc8")
        self.assertEqual(tc.parse_control_command(b"\x00"), (tc.CMD_UNLOCK, None))
        self.assertEqual(tc.parse_control_command(b"\x82\x00\x07"), (tc.CMD_SET_VR, 7))

    def test_invalid(self):
        for bad in (b"", b"\x01", b"\x00\x00", b"\x82\x01\x00", b"\x82\x00", b"\x83\x00\x01"):
            with self.assertRaises(ControlCommandError):
                tc.parse_control_command(bad)


class TestSegments(unittest.TestCase):
    def test_header(self):
        self.assertEqual(tc.Segment(0x21, b"ab").pack(), b"\xe1ab")
        s = tc.Segment.unpack(b"\x45xyz")
        self.assertEqual((s.flags, s.map_id, s.data), (tc.SEG_FIRST, 5, b"xyz"))
        with self.assertRaises(FrameTooShortError):
            tc.Segment.unpack(b"")

    def test_segment_and_reassemble(self):
        unit = bytes(range(250))
        segs = tc.segment(unit, 9, 100)
        self.assertEqual([s.flags for s in segs], [tc.SEG_FIRST, tc.SEG_CONTINUING, tc.SEG_LAST])
        r = tc.Reassembler()
        self.assertIsNone(r.push(segs[0]))
        self.assertIsNone(r.push(segs[1]))
        self.assertEqual(r.push(segs[2]), unit)
        self.assertEqual(tc.segment(b"abc", 1, 3)[0].flags, tc.SEG_UNSEGMENTED)

    def test_maps_are_independent_and_strays_dropped(self):
        r = tc.Reassembler()
        a = tc.segment(b"A" * 20, 1, 10)
        b = tc.segment(b"B" * 20, 2, 10)
        self.assertIsNone(r.push(a[0]))
        self.assertIsNone(r.push(b[0]))
        self.assertEqual(r.push(b[1]), b"B" * 20)
        self.assertEqual(r.push(a[1]), b"A" * 20)
        self.assertIsNone(r.push(a[1]))  # last without first
        self.assertEqual(r.dropped, 1)


class TestClcw(unittest.TestCase):
    def test_layout(self):
        c = Clcw(vcid=5, report=0x42, lockout=True, retransmit=True, farm_b=3, status=2)
        # type 0, version 00, status 010, COP 01 | VCID 000101, spare 00 |
        # noRF 0, bitlock 0, lockout 1, wait 0, retransmit 1, FARM-B 11, spare 0 | N(R)
        self.assertEqual(c.pack(), bytes((0x09, 0x14, 0x2E, 0x42)))
        self.assertEqual(Clcw.unpack(c.pack()), c)

    def test_errors(self):
        with self.assertRaises(FrameTooShortError):
            Clcw.unpack(b"\x01\x00\x00")
        with self.assertRaises(FrameHeaderError):
            Clcw.unpack(b"\x81\x00\x00\x00")


if __name__ == "__main__":
    unittest.main()
