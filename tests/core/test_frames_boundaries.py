"""TC frame layer edges: FARM-1 windows and buffer at their limits, FOP-1 directives and
counters where the state table turns, an SDLS frame with nothing after its segment header,
and the CLTU codeblock an error names."""

import unittest

from obsw.frames import cltu, farm, sdls
from obsw.frames import fop as F
from obsw.frames.clcw import Clcw
from obsw.frames.errors import CltuError
from obsw.frames.tc import TcFrame

KEY = bytes(range(32))


def bd(data=b"b"):
    return TcFrame(1, 0, data, 0, True)


class TestFarmLimits(unittest.TestCase):
    def test_window_two_is_the_smallest(self):
        f = farm.Farm1(0, window=2)
        self.assertEqual((f.positive, f.negative), (1, 1))
        for w in (0, 1, 3, 256):
            with self.assertRaises(ValueError):
                farm.Farm1(0, window=w)
        self.assertEqual(farm.Farm1(0, window=254).positive, 127)

    def test_positive_window_one_is_the_smallest(self):
        f = farm.Farm1(0, window=10, positive=1, negative=0)
        self.assertEqual((f.positive, f.negative), (1, 0))
        self.assertEqual(farm.Farm1(0, window=10, positive=10, negative=0).positive, 10)
        for pw, nw in ((0, 0), (11, 0), (1, -1)):
            with self.assertRaises(ValueError):
                farm.Farm1(0, window=10, positive=pw, negative=nw)

    def test_status_field_is_zero_unless_given(self):
        self.assertEqual(farm.Farm1(0).clcw().status, 0)
        self.assertEqual(farm.Farm1(0, status=7).clcw().status, 7)

    def test_room_for_64_bd_frames_beyond_the_buffer(self):
        f = farm.Farm1(0, buffer_size=1)
        for _ in range(1 + 64):
            self.assertEqual(f.on_frame(bd()), farm.ACCEPT)
        self.assertEqual((f.on_frame(bd()), f.bd_dropped), (farm.DISCARD, 1))
        f.take()
        self.assertEqual(f.on_frame(bd()), farm.ACCEPT)


class TestFopEdges(unittest.TestCase):
    def test_notification_kinds_are_distinct(self):
        kinds = (F.ACCEPT, F.REJECT, F.POSITIVE_CONFIRM, F.NEGATIVE_CONFIRM, F.ALERT, F.SUSPEND)
        self.assertEqual(len(set(kinds)), len(kinds))
        self.assertEqual(F.NOTIFICATION_NAMES[F.POSITIVE_CONFIRM], "confirm")
        self.assertEqual(F.NOTIFICATION_NAMES[F.NEGATIVE_CONFIRM], "negative")

    def test_e26_unlock_while_a_bc_frame_is_out_is_rejected(self):
        f = F.Fop1(1, 0, auto_accept=False)
        f.directive(F.INITIATE_AD_WITH_UNLOCK, now=0)  # BC frame handed down, not yet taken
        f.directive(F.TERMINATE_AD, now=0)
        f.take_frames()
        f.take_notifications()
        self.assertFalse(f.bc_out)
        rid = f.directive(F.INITIATE_AD_WITH_UNLOCK, now=1)
        self.assertEqual(f.last_event, 26)
        self.assertEqual(f.take_notifications(), [(F.REJECT, rid, None)])
        self.assertEqual((f.take_frames(), f.state), ([], F.INITIAL))

    def test_first_ad_frame_after_a_retransmitted_bc_counts_from_one(self):
        f = F.Fop1(1, 0, t1=2, transmission_limit=2)
        f.directive(F.INITIATE_AD_WITH_UNLOCK, now=0)
        f.tick(2)  # the BC frame retransmitted: Transmission_Count 2
        f.on_clcw(Clcw(vcid=0, report=0), now=3)
        self.assertEqual(f.state, F.ACTIVE)
        f.take_frames()
        f.take_notifications()
        f.send_ad(b"x", now=3)
        self.assertEqual(f.transmission_count, 1)
        f.tick(5)  # T1 expires once: below the limit, the frame goes again
        self.assertEqual([fr.data for fr in f.take_frames()], [b"x", b"x"])
        self.assertEqual([n for n in f.take_notifications() if n[0] == F.ALERT], [])
        self.assertEqual(f.state, F.ACTIVE)


class TestSdlsEdges(unittest.TestCase):
    def test_segment_header_alone_is_secured(self):
        sec = sdls.TcSecurity([sdls.SecurityAssociation(1, 0, KEY)])
        out = sec.apply(0x42, 0, b"\x01")
        self.assertEqual(out[:3], b"\x01\x00\x01")  # segment header, SPI 1
        self.assertEqual(len(out), 1 + 2 + 4 + 16)
        with self.assertRaises(sdls.SdlsError):
            sec.apply(0x42, 0, b"")

    def test_repr_names_the_map(self):
        self.assertIn("map=any", repr(sdls.SecurityAssociation(1, 0, KEY)))
        self.assertIn("map=5", repr(sdls.SecurityAssociation(1, 0, KEY, map_id=5)))


class TestCltuBlockNamed(unittest.TestCase):
    def test_an_uncorrectable_later_codeblock_is_named(self):
        # codeblocks 0..9; the index is counted in 8-octet codeblocks, not 7-octet payloads
        for k in (7, 8, 9):
            c = bytearray(cltu.encode(bytes(70)))
            c[2 + 8 * k] ^= 0x03
            with self.assertRaises(CltuError) as cm:
                cltu.decode(bytes(c))
            self.assertEqual(cm.exception.block, k)


if __name__ == "__main__":
    unittest.main()
