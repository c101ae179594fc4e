"""The frame processor: two redundant links, duplicates, bad frames, APID routing, TM out."""

import unittest

from obsw.frames import cltu, processor, tc
from obsw.frames.asm import CaduDecoder
from obsw.frames.tm_demux import TmDemultiplexer

SCID = 0x42


def tc_packet(apid, payload):
    n = len(payload)
    return bytes((0x18 | apid >> 8, apid & 0xFF, 0xC0, 0, (n - 1) >> 8, (n - 1) & 0xFF)) + payload


def tm_packet(apid, payload):
    n = len(payload)
    return bytes((0x08 | apid >> 8, apid & 0xFF, 0xC0, 0, (n - 1) >> 8, (n - 1) & 0xFF)) + payload


def cltu_of(data, seq=0, map_id=1, bypass=False, control=False, vcid=0, scid=SCID):
    body = data if control else tc.Segment(map_id, data).pack()
    return cltu.encode(tc.TcFrame(scid, vcid, body, seq, bypass, control).pack())


class Harness:
    def __init__(self, **kw):
        self.routed = []
        self.essential = []
        self.p = processor.FrameProcessor(
            SCID,
            lambda apid, pkt: self.routed.append((apid, pkt)),
            lambda unit: self.essential.append(unit),
            essential_map=63,
            tm_frame_length=80,
            **kw,
        )


class TestTelecommand(unittest.TestCase):
    def test_frame_on_both_links_accepted_once(self):
        h = Harness()
        c = cltu_of(tc_packet(0x21, b"cmd"))
        h.p.receive(0, c, 0.0)
        h.p.receive(1, c, 0.01)
        self.assertEqual(h.routed, [(0x21, tc_packet(0x21, b"cmd"))])
        self.assertEqual(h.p.counters["duplicates"], 1)
        self.assertEqual(h.p.counters["accepted"], 1)

    def test_bd_frame_on_both_links_accepted_once(self):
        h = Harness()
        c = cltu_of(tc_packet(0x21, b"bd"), bypass=True)
        h.p.receive(1, c, 0.0)
        h.p.receive(0, c, 0.0)
        self.assertEqual(len(h.routed), 1)
        self.assertEqual(h.p.farms[0].farm_b, 1)

    def test_repeated_frame_on_one_link_is_not_a_duplicate(self):
        h = Harness()
        c = cltu_of(tc_packet(0x21, b"x"), bypass=True)
        h.p.receive(0, c, 0.0)
        h.p.receive(0, c, 0.1)
        self.assertEqual(len(h.routed), 2)

    def test_bit_error_corrected_on_one_link(self):
        h = Harness()
        c = cltu_of(tc_packet(0x21, b"fix me"))
        bad = bytearray(c)
        bad[7] ^= 0x04
        h.p.receive(0, bytes(bad), 0.0)
        self.assertEqual(h.routed, [(0x21, tc_packet(0x21, b"fix me"))])
        self.assertEqual(h.p.counters["corrected_bits"], 1)
        h.p.receive(1, c, 0.0)
        self.assertEqual(len(h.routed), 1)

    def test_uncorrectable_and_bad_fecf_dropped_and_counted(self):
        h = Harness()
        c = bytearray(cltu_of(tc_packet(0x21, b"x")))
        c[4] ^= 0x18
        h.p.receive(0, bytes(c), 0.0)
        self.assertEqual(h.p.counters["cltus_aborted"], 1)
        raw = bytearray(tc.TcFrame(SCID, 0, tc.Segment(1, tc_packet(1, b"y")).pack()).pack())
        raw[-1] ^= 1
        h.p.receive(0, cltu.encode(bytes(raw)), 0.0)
        self.assertEqual(h.p.counters["bad_fecf"], 1)
        self.assertEqual(h.routed, [])

    def test_foreign_frames_are_invalid(self):
        h = Harness()
        h.p.receive(0, cltu_of(tc_packet(1, b"x"), scid=7), 0.0)
        h.p.receive(0, cltu_of(tc_packet(1, b"x"), vcid=5), 0.0)
        self.assertEqual(h.p.counters["invalid_frames"], 2)

    def test_several_packets_in_one_frame(self):
        h = Harness()
        h.p.receive(0, cltu_of(tc_packet(0x30, b"a") + tc_packet(0x31, b"bb")), 0.0)
        self.assertEqual([a for a, _ in h.routed], [0x30, 0x31])

    def test_essential_map_goes_to_sink(self):
        h = Harness()
        h.p.receive(0, cltu_of(tc_packet(0x7F, b"hpc"), map_id=63, bypass=True), 0.0)
        self.assertEqual(h.essential, [tc_packet(0x7F, b"hpc")])
        self.assertEqual(h.routed, [])

    def test_segmented_packet(self):
        h = Harness()
        pkt = tc_packet(0x22, bytes(range(100)))
        for k, seg in enumerate(tc.segment(pkt, 2, 40)):
            frame = tc.TcFrame(SCID, 0, seg.pack(), k)
            h.p.receive(0, cltu.encode(frame.pack()), 0.0)
        self.assertEqual(h.routed, [(0x22, pkt)])

    def test_farm_sequence(self):
        h = Harness()
        h.p.receive(0, cltu_of(tc_packet(1, b"late"), seq=1), 0.0)
        self.assertEqual(h.p.counters["discarded"], 1)
        self.assertTrue(h.p.farms[0].retransmit)
        h.p.receive(0, cltu_of(tc.set_vr_command(1), control=True, bypass=True), 0.0)
        h.p.receive(0, cltu_of(tc_packet(1, b"late"), seq=1), 0.0)
        self.assertEqual(len(h.routed), 1)


class TestTelemetry(unittest.TestCase):
    def decode(self, cadus):
        dec = CaduDecoder(80)
        demux = TmDemultiplexer(SCID)
        got = []
        for c in cadus:
            for f in dec.feed(c):
                got.extend(demux.feed(f))
        return got, demux

    def test_packets_out_with_clcw(self):
        h = Harness()
        h.p.receive(0, cltu_of(tc_packet(1, b"x")), 0.0)
        pkts = [tm_packet(0x40, bytes(30)), tm_packet(0x41, bytes(90))]
        for p in pkts:
            self.assertTrue(h.p.send_packet(p))
        got, demux = self.decode(h.p.tm_output(1.0))
        self.assertEqual(got, pkts)
        self.assertEqual(demux.clcw.report, 1)

    def test_idle_frame_reports_clcw_when_due(self):
        h = Harness(clcw_period=5.0)
        self.assertEqual(len(h.p.tm_output(0.0)), 1)  # first report
        self.assertEqual(h.p.tm_output(1.0), [])
        h.p.receive(0, cltu_of(tc_packet(1, b"x")), 2.0)
        out = h.p.tm_output(2.0)  # FARM changed: report now
        got, demux = self.decode(out)
        self.assertEqual((got, demux.clcw.report), ([], 1))
        self.assertEqual(len(h.p.tm_output(7.5)), 1)

    def test_virtual_channel_by_apid(self):
        from obsw.frames.tm_mux import TmVirtualChannel

        rt = TmVirtualChannel(0, 2)
        ess = TmVirtualChannel(3, 9)
        h = Harness(tm_channels=[rt, ess], tm_vc_of_apid={0x50: 3})
        h.p.send_packet(tm_packet(0x10, b"normal"))
        h.p.send_packet(tm_packet(0x50, b"essential"))
        self.assertEqual((rt.packets, ess.packets), (1, 1))

    def test_split_packets(self):
        pkts, left = processor.split_packets(tc_packet(1, b"ab") + b"\x00\x01")
        self.assertEqual((pkts, left), ([tc_packet(1, b"ab")], 2))


if __name__ == "__main__":
    unittest.main()
