"""The downlink at the radio's rate: pacing, VC priorities with live telemetry flushed at once,
idle frames only when nothing waits, the spill store and its overflow report."""

import unittest

from obsw.frames import processor
from obsw.frames.asm import CaduDecoder
from obsw.frames.downlink import Downlink, Spill
from obsw.frames.tm import TmFrame
from obsw.frames.tm_coding import TmDecoder, TmEncoder
from obsw.frames.tm_demux import TmDemultiplexer
from obsw.frames.tm_mux import TmMultiplexer, TmVirtualChannel
from obsw.frames.tm_plan import PLAYBACK_VCID, REALTIME_VCID

SCID = 0x42
LENGTH = 64
IDLE_VC = 7


def tm_packet(apid, payload):
    n = len(payload)
    return bytes((0x08 | apid >> 8, apid & 0xFF, 0xC0, 0, (n - 1) >> 8, (n - 1) & 0xFF)) + payload


def fp(**kw):
    return processor.FrameProcessor(SCID, lambda a, p: None, tm_frame_length=LENGTH, **kw)


def frames_of(cadus):
    dec = CaduDecoder(LENGTH)
    out = []
    for c in cadus:
        for raw in dec.feed(c):
            out.append(TmFrame.unpack(raw))
    return out


class DownlinkTest(unittest.TestCase):
    def test_frame_time_and_lead(self):
        d = Downlink(1000, 125)  # one second per frame
        self.assertAlmostEqual(d.frame_time, 1.0)
        self.assertEqual(d.due(0.0), 2)  # the one on the air and one beyond
        self.assertEqual(d.due(0.5), 0)
        self.assertEqual(d.due(0.999), 0)
        self.assertEqual(d.due(1.0), 1)
        self.assertEqual(d.due(2.5), 1)
        self.assertEqual(d.frames, 4)

    def test_no_credit_saved_while_starved(self):
        d = Downlink(1000, 125)
        d.due(0.0)
        self.assertEqual(d.due(100.0), 2)  # as at the start, not 100 frames at once

    def test_rate_must_be_positive(self):
        self.assertRaises(ValueError, Downlink, 0, 10)

    def test_paced_output_follows_the_rate(self):
        f = fp(downlink_bps=(LENGTH + 4) * 8)  # one frame per second
        t = 0.0
        n = 0
        while t < 10.0:
            n += len(f.tm_output(t))
            t += 0.25
        self.assertEqual(n, 11)  # frames handed by 9.75 s: 10 sent or on the air, one ahead

    def test_idle_only_when_nothing_waits(self):
        f = fp(downlink_bps=(LENGTH + 4) * 8)
        got = frames_of(f.tm_output(0.0))
        self.assertEqual([x.vcid for x in got], [IDLE_VC, IDLE_VC])
        f.send_packet(tm_packet(5, b"x" * 10), PLAYBACK_VCID)  # a partial frame, low priority
        got = frames_of(f.tm_output(1.0))
        self.assertEqual([x.vcid for x in got], [PLAYBACK_VCID])  # padded rather than idle
        self.assertEqual(f.counters["tm_idle_frames"], 2)

    def test_live_telemetry_flushed_before_full_playback_frames(self):
        f = fp(downlink_bps=(LENGTH + 4) * 8)
        for _ in range(20):
            f.send_packet(tm_packet(5, b"p" * 40), PLAYBACK_VCID)
        f.tm_output(0.0)
        f.send_packet(tm_packet(1, b"hk"), REALTIME_VCID)  # much less than a frame
        got = frames_of(f.tm_output(1.0))
        self.assertEqual([x.vcid for x in got], [REALTIME_VCID])

    def test_low_priority_partial_frames_wait_for_full_ones(self):
        f = fp(downlink_bps=(LENGTH + 4) * 8, tm_urgent=3)  # real time (2) not urgent here
        for _ in range(4):
            f.send_packet(tm_packet(5, b"p" * 40), PLAYBACK_VCID)
        f.send_packet(tm_packet(1, b"hk"), REALTIME_VCID)
        got = frames_of(f.tm_output(0.0))
        self.assertEqual([x.vcid for x in got], [PLAYBACK_VCID, PLAYBACK_VCID])

    def test_coded_frames_take_the_coded_length(self):
        enc = TmEncoder(LENGTH, "concatenated", 16, 1)
        self.assertEqual(enc.channel_length, 2 * (LENGTH + 32 + 4))
        f = fp(downlink_bps=enc.channel_length * 8, tm_coding=enc)  # one frame per second
        f.send_packet(tm_packet(1, b"hello"), REALTIME_VCID)
        out = f.tm_output(0.0)
        self.assertEqual([len(c) for c in out], [enc.channel_length] * 2)
        dec = TmDecoder(LENGTH, "concatenated", 16, 1)
        frames = dec.feed_octets(b"".join(out) + b"\x55" * 64) + dec.flush()
        demux = TmDemultiplexer(SCID)
        packets = []
        for d in frames:
            packets += demux.on_frame(TmFrame.unpack(d.data))
        self.assertEqual(packets, [tm_packet(1, b"hello")])


class SpillTest(unittest.TestCase):
    def channels(self, capacity):
        return [TmVirtualChannel(0, 1, capacity)]

    def test_spilled_packets_keep_their_order(self):
        f = processor.FrameProcessor(
            SCID, lambda a, p: None, tm_frame_length=LENGTH, tm_channels=self.channels(60),
            downlink_bps=(LENGTH + 4) * 8, tm_spill=1000,
        )  # fmt: skip
        sent = [tm_packet(1, bytes((i,)) * 20) for i in range(10)]
        for p in sent:
            self.assertTrue(f.send_packet(p, 0))
        self.assertEqual(f.counters["tm_spilled"], 8)  # two fit the 60-octet channel
        demux = TmDemultiplexer(SCID)
        got = []
        t = 0.0
        while len(got) < 10 and t < 60:
            for x in frames_of(f.tm_output(t)):
                got += demux.on_frame(x) if x.vcid == 0 else []
            t += 1.0
        self.assertEqual(got, sent)
        self.assertEqual(f.counters["tm_dropped"], 0)

    def test_overflow_is_reported_never_silent(self):
        f = processor.FrameProcessor(
            SCID, lambda a, p: None, tm_frame_length=LENGTH, tm_channels=self.channels(30),
            tm_spill=52,
        )  # fmt: skip
        reports = []
        f.overflow_listeners.append(lambda vcid, p: reports.append((vcid, len(p))))
        p = tm_packet(1, b"x" * 20)  # 26 octets
        self.assertTrue(f.send_packet(p, 0))  # in the channel
        self.assertTrue(f.send_packet(p, 0))  # spilled: 26 of 52
        self.assertTrue(f.send_packet(p, 0))  # spilled: 52 of 52, the edge
        self.assertFalse(f.send_packet(p, 0))  # one above
        self.assertEqual(reports, [(0, 26)])
        self.assertEqual(f.counters["tm_dropped"], 1)

    def test_without_spill_a_full_channel_reports_too(self):
        f = processor.FrameProcessor(
            SCID, lambda a, p: None, tm_frame_length=LENGTH, tm_channels=self.channels(26)
        )
        reports = []
        f.overflow_listeners.append(lambda vcid, p: reports.append(vcid))
        p = tm_packet(1, b"x" * 20)
        self.assertTrue(f.send_packet(p, 0))
        self.assertFalse(f.send_packet(p, 0))
        self.assertEqual(reports, [0])

    def test_refill_moves_what_fits(self):
        mux = TmMultiplexer(SCID, LENGTH, self.channels(30))
        s = Spill(100)
        self.assertTrue(s.put(0, b"a" * 20))
        self.assertTrue(s.put(0, b"b" * 20))
        s.refill(mux)
        self.assertEqual(mux.channel(0).pending(), 20)
        self.assertTrue(s.waiting(0))
        self.assertEqual(s.octets, 20)


if __name__ == "__main__":
    unittest.main()
