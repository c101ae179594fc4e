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


class TestFopLowerProcedures(unittest.TestCase):
    """FOP-1 with lower procedures that take frames when they say so (auto_accept off)."""

    def test_alert_codes_are_distinct(self):
        codes = (F.ALERT_LIMIT, F.ALERT_T1, F.ALERT_LOCKOUT, F.ALERT_SYNCH, F.ALERT_NNR)
        self.assertEqual(len(set(codes)), len(codes))
        self.assertEqual(F.ALERT_NAMES[F.ALERT_T1], "T1")
        self.assertEqual(F.ALERT_NAMES[F.ALERT_LOCKOUT], "LOCKOUT")

    def test_e22_a_second_bd_frame_before_the_first_is_taken(self):
        f = F.Fop1(1, 0, auto_accept=False)
        f.send_bd(b"a", now=0)
        rid = f.send_bd(b"b", now=0)
        self.assertEqual(f.last_event, 22)
        self.assertEqual(f.take_notifications()[-1], (F.REJECT, rid, None))
        self.assertEqual(([fr.data for fr in f.take_frames()], f.state), ([b"a"], F.INITIAL))

    def test_e45_bd_frame_taken_makes_room_for_the_next(self):
        f = F.Fop1(1, 0, auto_accept=False)
        f.send_bd(b"a", now=0)
        f.lower_response(2, True, now=0)
        self.assertTrue(f.bd_out)
        f.send_bd(b"b", now=0)
        self.assertEqual([fr.data for fr in f.take_frames()], [b"a", b"b"])

    def test_e46_bd_frame_refused_is_an_llif_alert(self):
        f = F.Fop1(1, 0, auto_accept=False)
        f.directive(F.INITIATE_AD_NO_CLCW, now=0)
        f.send_bd(b"a", now=0)
        f.take_notifications()
        f.lower_response(2, False, now=0)
        self.assertEqual(f.last_event, 46)
        self.assertIn((F.ALERT, None, F.ALERT_LLIF), f.take_notifications())
        self.assertEqual(f.state, F.INITIAL)

    def test_e28_set_vr_while_a_bc_frame_is_out_is_rejected(self):
        f = F.Fop1(1, 0, auto_accept=False)
        f.directive(F.INITIATE_AD_WITH_UNLOCK, now=0)
        f.directive(F.TERMINATE_AD, now=0)
        f.take_frames()
        f.take_notifications()
        rid = f.directive(F.INITIATE_AD_WITH_SET_VR, 5, now=1)
        self.assertEqual(f.last_event, 28)
        self.assertEqual(f.take_notifications(), [(F.REJECT, rid, None)])
        self.assertEqual((f.take_frames(), f.vs), ([], 0))

    def test_a_retransmitted_bc_frame_waits_for_the_lower_procedures(self):
        f = F.Fop1(1, 0, t1=1, transmission_limit=5, auto_accept=False)
        f.directive(F.INITIATE_AD_WITH_UNLOCK, now=0)
        f.lower_response(1, True, now=0)  # the BC frame taken
        self.assertEqual(len(f.take_frames()), 1)
        f.tick(1)  # retransmitted, handed down again: not taken yet
        self.assertEqual(len(f.take_frames()), 1)
        self.assertFalse(f.bc_out)
        f.tick(2)  # the timer again, the frame still not taken: nothing more goes down
        self.assertEqual(f.take_frames(), [])
        f.lower_response(1, True, now=2.5)
        self.assertEqual(len(f.take_frames()), 1)  # now the pending retransmission goes


class TestFopDirectiveLimits(unittest.TestCase):
    def verdict(self, kind, qualifier):
        f = F.Fop1(1, 0)
        rid = f.directive(kind, qualifier, now=0)
        return [n[0] for n in f.take_notifications() if n[1] == rid]

    def test_set_t1_needs_more_than_zero(self):
        self.assertEqual(self.verdict(F.SET_T1, 0), [F.REJECT])
        self.assertEqual(self.verdict(F.SET_T1, 1), [F.ACCEPT, F.POSITIVE_CONFIRM])

    def test_set_window_1_to_255(self):
        for k, ok in ((0, False), (1, True), (255, True), (256, False)):
            want = [F.ACCEPT, F.POSITIVE_CONFIRM] if ok else [F.REJECT]
            self.assertEqual(self.verdict(F.SET_WINDOW, k), want, k)

    def test_set_transmission_limit_at_least_1(self):
        self.assertEqual(self.verdict(F.SET_TRANSMISSION_LIMIT, 0), [F.REJECT])
        self.assertEqual(self.verdict(F.SET_TRANSMISSION_LIMIT, 1), [F.ACCEPT, F.POSITIVE_CONFIRM])

    def test_set_vs_0_to_255(self):
        for k, ok in ((0, True), (255, True), (256, False), (-1, False)):
            want = [F.ACCEPT, F.POSITIVE_CONFIRM] if ok else [F.REJECT]
            self.assertEqual(self.verdict(F.SET_VS, k), want, k)


class TestFopWindowAndTimeouts(unittest.TestCase):
    def active(self, **kw):
        f = F.Fop1(1, 0, **kw)
        f.directive(F.INITIATE_AD_NO_CLCW, now=0)
        f.take_notifications()
        return f

    def test_window_of_one_holds_the_second_frame(self):
        f = self.active(window=1)
        f.send_ad(b"a", now=0)
        f.send_ad(b"b", now=0)
        self.assertEqual([fr.data for fr in f.take_frames()], [b"a"])
        f.on_clcw(Clcw(vcid=0, report=1), now=1)
        self.assertEqual([fr.data for fr in f.take_frames()], [b"b"])

    def test_window_of_two_sends_both(self):
        f = self.active(window=2)
        f.send_ad(b"a", now=0)
        f.send_ad(b"b", now=0)
        self.assertEqual([fr.data for fr in f.take_frames()], [b"a", b"b"])

    def test_e104_timeout_type_1_below_the_limit_retransmits(self):
        f = self.active(t1=1, transmission_limit=3, timeout_type=1)
        f.send_ad(b"a", now=0)
        f.tick(1)
        self.assertEqual(f.last_event, 104)
        self.assertEqual([fr.data for fr in f.take_frames()], [b"a", b"a"])
        self.assertEqual((f.state, f.suspend_state), (F.ACTIVE, 0))


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


class TestSdlsLimits(unittest.TestCase):
    def test_states_and_outcomes_are_distinct_and_named(self):
        states = (sdls.SA_UNKEYED, sdls.SA_KEYED, sdls.SA_OPERATIONAL, sdls.SA_EXPIRED)
        self.assertEqual([sdls.SA_STATE_NAMES[s] for s in states], list(sdls.SA_STATE_NAMES))
        outcomes = (sdls.OK, sdls.BAD_SPI, sdls.NOT_OPERATIONAL, sdls.BAD_MAC, sdls.REPLAY)
        self.assertEqual(len(set(outcomes + (sdls.TOO_SHORT,))), 6)
        self.assertIn("unkeyed", repr(sdls.SecurityAssociation(1, 0)))

    def test_replay_window_sizes(self):
        self.assertEqual(sdls.ReplayWindow(1).size, 1)
        self.assertEqual(sdls.ReplayWindow(sdls.MAX_WINDOW).size, sdls.MAX_WINDOW)
        for size in (0, sdls.MAX_WINDOW + 1):
            with self.assertRaises(sdls.SdlsError):
                sdls.ReplayWindow(size)
        self.assertEqual(sdls.ReplayWindow(8, ahead=1).ahead, 1)
        with self.assertRaises(sdls.SdlsError):
            sdls.ReplayWindow(8, ahead=0)

    def test_numbers_are_not_reserved_in_blocks_unless_asked(self):
        sa = sdls.SecurityAssociation(1, 0, KEY)
        sec = sdls.TcSecurity([sa])
        sec.apply(0x42, 0, b"\x01pkt")
        sec.reserve(sa)
        self.assertEqual((sa.reserve_block, sa.sn_reserved), (0, sa.sn_sent))

    def test_a_keyed_sa_not_started_is_not_operational(self):
        sa = sdls.SecurityAssociation(1, 0, KEY)
        sec = sdls.TcSecurity([sa])
        raw = TcFrame(0x42, 0, sec.apply(0x42, 0, b"\x01pkt"), 0, True).pack()
        sa.state = sdls.SA_KEYED
        self.assertEqual(sec.process(raw, len(raw))[0], sdls.NOT_OPERATIONAL)
        self.assertEqual((sec.counters["sa_not_operational"], sec.counters["bad_spi"]), (1, 0))

    def test_without_segment_headers(self):
        sec = sdls.TcSecurity([sdls.SecurityAssociation(1, 0, KEY)], segment_header=False)
        data = sec.apply(0x42, 0, b"pkt", bypass=True)
        self.assertEqual(data[:2], b"\x00\x01")  # the SPI first
        raw = TcFrame(0x42, 0, data, 0, True).pack()
        outcome, sa, sn, clear = sec.process(raw, len(raw))
        self.assertEqual((outcome, sa.spi, sn, clear), (sdls.OK, 1, 1, b"pkt"))

    def test_shortest_frame_that_names_an_spi(self):
        sec = sdls.TcSecurity([sdls.SecurityAssociation(1, 0, KEY)])
        ten = TcFrame(0x42, 0, b"\x01\x00\x63", 0, True).pack()  # header, MAP, SPI, FECF
        self.assertEqual(len(ten), 10)
        self.assertEqual(sec.process(ten, 10)[0], sdls.BAD_SPI)
        nine = TcFrame(0x42, 0, b"\x01\x00", 0, True).pack()
        self.assertEqual(sec.process(nine, 9)[0], sdls.TOO_SHORT)


class TestCltuBlockNamed(unittest.TestCase):
    def test_an_uncorrectable_later_codeblock_is_named(self):
        # codeblocks 0..9; the index is counted in 8-octet codeblocks, not 7-octet payloads
        for k in (7, 8, 9):
            c = bytearray(cltu.encode(bytes(70)))
            c[2 + 8 * k] ^= 0x03
            with self.assertRaises(CltuError) as cm:
                cltu.decode(bytes(c))
            self.assertEqual(cm.exception.block, k)


class TestSdlsEventIds(unittest.TestCase):
    def test_each_rejection_has_its_own_event_in_outcome_order(self):
        # the default IDs the spacecraft database gives frames.tc_<outcome> (0xFF31 up)
        self.assertEqual(len(sdls.EVENT_IDS), len(sdls.OUTCOME_NAMES))
        self.assertEqual(sdls.EVENT_IDS[sdls.OK], 0)  # accepted: no event
        for outcome in range(1, len(sdls.OUTCOME_NAMES)):
            self.assertEqual(sdls.EVENT_IDS[outcome], 0xFF30 + outcome)


if __name__ == "__main__":
    unittest.main()


class TestCltuLengths(unittest.TestCase):
    def test_a_1024_octet_frame_is_the_longest_the_decoder_takes(self):
        longest = bytes(range(256)) * 4  # 147 codeblocks
        dec = cltu.CltuDecoder()
        self.assertEqual([d[:1024] for d in dec.feed(cltu.encode(longest))], [longest])
        self.assertEqual(dec.feed(cltu.encode(longest + bytes(7))), [])  # 148 codeblocks
        self.assertEqual((dec.cltus, dec.aborted), (1, 1))

    def test_a_body_not_whole_codeblocks_names_its_length(self):
        c = cltu.encode(bytes(7))
        with self.assertRaises(CltuError) as cm:
            cltu.decode(c[:-8] + b"\x00" + c[-8:])
        self.assertIn("body of 17 bytes", str(cm.exception))
