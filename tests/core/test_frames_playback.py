"""TM virtual channel plan of the frame processor: real-time, playback and essential VCs,
packets sent for a VC come out in frames of that VC, channels served by priority."""

import unittest

from obsw.frames import processor
from obsw.frames.asm import CaduDecoder
from obsw.frames.tm import TmFrame
from obsw.frames.tm_demux import TmDemultiplexer
from obsw.frames.tm_mux import TmVirtualChannel
from obsw.frames.tm_plan import (
    ESSENTIAL_VCID,
    PLAYBACK_VCID,
    REALTIME_VCID,
    TmPlanError,
    plan_channels,
    tm_plan,
)

SCID = 0x42
LENGTH = 80


def tm_packet(apid, payload):
    n = len(payload)
    return bytes((0x08 | apid >> 8, apid & 0xFF, 0xC0, 0, (n - 1) >> 8, (n - 1) & 0xFF)) + payload


def fp(**kw):
    return processor.FrameProcessor(SCID, lambda apid, pkt: None, tm_frame_length=LENGTH, **kw)


def decode(cadus):
    """(VC ID, packet) for every packet, and the VC ID of every frame, in order."""
    dec = CaduDecoder(LENGTH)
    demux = TmDemultiplexer(SCID)
    packets = []
    frames = []
    for c in cadus:
        for raw in dec.feed(c):
            f = TmFrame.unpack(raw)
            frames.append(f.vcid)
            for p in demux.on_frame(f):
                packets.append((f.vcid, p))
    return packets, frames


class TestPlan(unittest.TestCase):
    def test_defaults(self):
        self.assertEqual(tm_plan(), {"realtime": 0, "playback": 1, "essential": 6})
        self.assertEqual((REALTIME_VCID, PLAYBACK_VCID, ESSENTIAL_VCID), (0, 1, 6))

    def test_configured_ids(self):
        plan = tm_plan({"playback": 2, "essential": 5})
        self.assertEqual(plan, {"realtime": 0, "playback": 2, "essential": 5})
        chans = plan_channels(plan, 1024)
        self.assertEqual([(c.name, c.vcid, c.capacity) for c in chans][1], ("playback", 2, 1024))

    def test_bad_plans_refused(self):
        for bad, role in (
            ({"playback": 0}, "playback"),  # the real-time VC's
            ({"essential": 7}, "essential"),  # idle frames
            ({"realtime": -1}, "realtime"),
            ({"playback": "1"}, "playback"),
            ({"replay": 3}, "replay"),
        ):
            with self.assertRaises(TmPlanError) as ctx:
                tm_plan(bad)
            self.assertEqual(ctx.exception.role, role)
            self.assertIsInstance(ctx.exception, ValueError)


class TestPlayback(unittest.TestCase):
    def test_processor_has_the_plan_channels(self):
        p = fp()
        self.assertEqual(sorted(c.vcid for c in p.mux.channels), [0, 1, 6])
        self.assertEqual((p.tm_default_vcid, p.playback_vcid), (0, 1))
        p = fp(tm_plan={"realtime": 3, "playback": 4})
        self.assertEqual((p.tm_default_vcid, p.playback_vcid), (3, 4))

    def test_playback_on_vc1_realtime_on_vc0(self):
        p = fp()
        live = tm_packet(0x10, b"live housekeeping")
        stored = tm_packet(0x10, b"stored housekeeping")  # same APID: the VC is chosen
        self.assertTrue(p.send_packet(live))
        self.assertTrue(p.send_playback(stored))
        self.assertTrue(p.send_packet(stored, PLAYBACK_VCID))
        packets, _ = decode(p.tm_output(0.0))
        self.assertEqual(sorted(packets), sorted([(0, live), (1, stored), (1, stored)]))
        self.assertEqual(p.counters["tm_packets"], 3)

    def test_apid_mapped_to_the_essential_vc(self):
        p = fp(tm_vc_of_apid={0x7E: ESSENTIAL_VCID})
        p.send_packet(tm_packet(0x7E, b"hptm"))
        p.send_packet(tm_packet(0x11, b"normal"))
        packets, _ = decode(p.tm_output(0.0))
        self.assertEqual(
            sorted(packets), [(0, tm_packet(0x11, b"normal")), (6, tm_packet(0x7E, b"hptm"))]
        )

    def test_priorities_essential_then_realtime_then_playback(self):
        p = fp(tm_vc_of_apid={0x7E: ESSENTIAL_VCID})
        d = p.mux.data_length
        body = bytes(d - 6)  # one packet fills one frame exactly
        for _k in range(3):
            p.send_playback(tm_packet(0x10, body))
        for _k in range(2):
            p.send_packet(tm_packet(0x10, body))
        p.send_packet(tm_packet(0x7E, body))
        _, frames = decode(p.tm_output(0.0))
        self.assertEqual(frames, [6, 0, 0, 1, 1, 1])

    def test_realtime_arriving_during_playback_goes_first(self):
        p = fp()
        d = p.mux.data_length
        for _k in range(4):
            p.send_playback(tm_packet(0x10, bytes(d - 6)))
        first = p.mux.frame()
        self.assertEqual(first.vcid, 1)
        p.send_packet(tm_packet(0x10, bytes(d - 6)))
        self.assertEqual(p.mux.frame().vcid, 0)
        rest = []
        while True:
            f = p.mux.frame()
            if f is None:
                break
            rest.append(f.vcid)
        self.assertEqual(rest, [1, 1, 1])

    def test_unknown_vc_counted(self):
        p = fp()
        self.assertFalse(p.send_packet(tm_packet(1, b"x"), 5))
        self.assertEqual(p.counters["tm_unknown_vc"], 1)
        self.assertEqual(p.counters["tm_packets"], 0)

    def test_explicit_channels_have_no_plan(self):
        rt = TmVirtualChannel(0, 2)
        ess = TmVirtualChannel(3, 9)
        p = fp(tm_channels=[rt, ess])
        self.assertIsNone(p.tm_plan)
        self.assertEqual(p.tm_default_vcid, 0)
        self.assertFalse(p.send_playback(tm_packet(1, b"x")))
        self.assertEqual(p.counters["tm_unknown_vc"], 1)
        p = fp(tm_channels=[TmVirtualChannel(0, 2), TmVirtualChannel(3, 9)], tm_default_vcid=3)
        p.send_packet(tm_packet(1, b"x"))
        self.assertEqual(p.mux.channel(3).packets, 1)

    def test_full_playback_channel_drops_and_counts(self):
        p = fp(tm_channels=plan_channels(tm_plan(), 64), tm_plan={})
        self.assertTrue(p.send_playback(tm_packet(1, bytes(40))))
        self.assertFalse(p.send_playback(tm_packet(1, bytes(40))))
        self.assertEqual(p.counters["tm_dropped"], 1)


if __name__ == "__main__":
    unittest.main()
