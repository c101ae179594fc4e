"""TM transfer frames (CCSDS 132.0-B), ASM and multiplexing of packets across frames."""

import unittest

from obsw.crc import crc16_ccitt
from obsw.frames import asm, tm, tm_demux, tm_mux
from obsw.frames.clcw import Clcw
from obsw.frames.errors import FecfError, FrameHeaderError, FrameTooShortError
from obsw.frames.randomizer import randomize_tm


def packet(apid, n, fill=0):
    # A TM space packet of n bytes in total (n >= 7), data bytes counting up from ``fill``.
    data = bytes((fill + i) & 0xFF for i in range(n - 6))
    return bytes((0x08 | apid >> 8, apid & 0xFF, 0xC0, 0, (n - 7) >> 8, (n - 7) & 0xFF)) + data


class TestFrame(unittest.TestCase):
    def test_header_layout(self):
        f = tm.TmFrame(
            0x2AB, 5, b"\x11" * 8, mc_count=0x12, vc_count=0x34, fhp=0x123, ocf=b"\x01\x02\x03\x04"
        )
        raw = f.pack()
        # version 00 | SCID 10 bits | VCID 3 | OCF flag | MC count | VC count | data field status
        self.assertEqual(raw[:6], bytes((0x2A, 0xBB, 0x12, 0x34, 0x19, 0x23)))
        self.assertEqual(len(raw), 6 + 8 + 4 + 2)
        self.assertEqual(raw[14:18], b"\x01\x02\x03\x04")
        self.assertEqual(crc16_ccitt(raw), 0)

    def test_round_trip_with_secondary_header(self):
        f = tm.TmFrame(7, 1, b"abc", 1, 2, 0, None, b"\xaa\xbb", sync=False, packet_order=True)
        raw = f.pack()
        self.assertEqual(raw[4] & 0x80, 0x80)
        self.assertEqual(raw[6], 2)
        g = tm.TmFrame.unpack(raw)
        self.assertEqual(
            (g.secondary_header, g.data, g.ocf, g.packet_order), (b"\xaa\xbb", b"abc", None, True)
        )
        self.assertEqual(g, f)
        self.assertEqual(tm.TmFrame.unpack(f.pack(False), fecf=False).data, b"abc")

    def test_errors(self):
        raw = bytearray(tm.TmFrame(7, 1, b"abcdef").pack())
        with self.assertRaises(FrameTooShortError):
            tm.TmFrame.unpack(raw[:7])
        bad = bytearray(raw)
        bad[7] ^= 4
        with self.assertRaises(FecfError):
            tm.TmFrame.unpack(bytes(bad))
        bad = bytearray(raw)
        bad[0] |= 0x80
        with self.assertRaises(FrameHeaderError):
            tm.TmFrame.unpack(bytes(bad[:-2]), fecf=False)
        with self.assertRaises(ValueError):
            tm.TmFrame(7, 8, b"").pack()


class TestAsm(unittest.TestCase):
    def test_cadu_and_decoder(self):
        frames = [bytes([k]) * 20 for k in range(3)]
        stream = b"\x00\x1a\xcf" + b"".join(asm.cadu(f) for f in frames) + b"\x1a\xcf\xfc\x1d\x00"
        self.assertEqual(asm.cadu(frames[0])[:4], b"\x1a\xcf\xfc\x1d")
        self.assertEqual(asm.cadu(frames[0])[4:], randomize_tm(frames[0]))
        dec = asm.CaduDecoder(20)
        out = []
        for i in range(0, len(stream), 7):
            out.extend(dec.feed(stream[i : i + 7]))
        self.assertEqual(out, frames)
        self.assertEqual(dec.skipped, 3)

    def test_not_randomized(self):
        dec = asm.CaduDecoder(5, randomize=False)
        self.assertEqual(dec.feed(asm.cadu(b"hello", randomize=False)), [b"hello"])


class TestMultiplexing(unittest.TestCase):
    def setUp(self):
        self.rt = tm_mux.TmVirtualChannel(0, priority=2)
        self.pb = tm_mux.TmVirtualChannel(1, priority=1)
        self.clcw = Clcw(vcid=0, report=3)
        self.mux = tm_mux.TmMultiplexer(0x55, 64, [self.pb, self.rt], lambda: self.clcw.pack())
        self.demux = tm_demux.TmDemultiplexer(0x55)

    def _pump(self, flush=True):
        out = []
        while True:
            f = self.mux.frame(flush)
            if f is None:
                return out
            out.append((f, self.demux.feed(f.pack())))

    def test_data_field_length(self):
        self.assertEqual(self.mux.data_length, 64 - 6 - 4 - 2)

    def test_spanning_packets_and_first_header_pointer(self):
        pkts = [packet(0x10, 30, 1), packet(0x11, 100, 2), packet(0x12, 9, 3)]
        for p in pkts:
            self.rt.push(p)
        result = self._pump()
        frames = [f for f, _ in result]
        got = [p for _, ps in result for p in ps]
        self.assertEqual(got, pkts)
        self.assertEqual([f.fhp for f in frames], [0, tm.FHP_NO_PACKET, 26])
        self.assertEqual([f.vc_count for f in frames], [0, 1, 2])
        self.assertEqual([f.mc_count for f in frames], [0, 1, 2])
        self.assertEqual(self.demux.clcw, self.clcw)

    def test_priority(self):
        self.pb.push(packet(0x20, 52))
        self.rt.push(packet(0x10, 52))
        frames = [f for f, _ in self._pump()]
        self.assertEqual([f.vcid for f in frames], [0, 1])

    def test_partial_frame_waits_unless_flushed(self):
        self.rt.push(packet(0x10, 20))
        self.assertIsNone(self.mux.frame(False))
        f = self.mux.frame(True)
        self.assertEqual(self.demux.feed(f.pack()), [packet(0x10, 20)])
        self.assertEqual(self.rt.pending(), 0)

    def test_short_gap_idle_packet_spills_into_next_frame(self):
        self.rt.push(packet(0x10, 48))  # leaves 4 bytes, less than an idle packet
        self.rt.push(packet(0x10, 7))
        got = [p for _, ps in self._pump() for p in ps]
        self.assertEqual(got, [packet(0x10, 48), packet(0x10, 7)])

    def test_only_idle_frame(self):
        f = self.mux.frame(True, True)
        self.assertEqual((f.vcid, f.fhp, len(f.data)), (7, tm.FHP_IDLE, 52))
        self.assertEqual(self.demux.feed(f.pack()), [])
        self.assertEqual(self.demux.clcw, self.clcw)

    def test_lost_frame_drops_spanning_packet_only(self):
        pkts = [packet(0x10, 40), packet(0x10, 60), packet(0x10, 60)]
        for p in pkts:
            self.rt.push(p)
        frames = []
        while True:
            f = self.mux.frame(True)
            if f is None:
                break
            frames.append(f)
        demux = tm_demux.TmDemultiplexer(0x55)
        got = []
        for k, f in enumerate(frames):
            if k != 2:
                got.extend(demux.feed(f.pack()))
        self.assertEqual([f.fhp for f in frames], [0, 48, tm.FHP_NO_PACKET, 4])
        self.assertEqual(got, pkts[:2])
        self.assertEqual(demux.channels[0].lost, 1)
        self.assertEqual(demux.mc_gaps, 1)

    def test_capacity(self):
        vc = tm_mux.TmVirtualChannel(2, capacity=20)
        self.assertTrue(vc.push(packet(1, 15)))
        self.assertFalse(vc.push(packet(1, 15)))
        self.assertEqual(vc.dropped, 1)

    def test_wrong_scid(self):
        f = tm.TmFrame(0x56, 0, bytes(52), ocf=bytes(4))
        with self.assertRaises(FrameHeaderError):
            self.demux.feed(f.pack())


if __name__ == "__main__":
    unittest.main()
