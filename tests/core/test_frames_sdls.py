"""TC security (SDLS): HMAC-SHA-256, SAs, the replay window, and the frame processor's verdicts."""

import unittest

from obsw.frames import cltu, processor, sdls, tc
from obsw.frames.sdls_keys import KeyFileError, dump_sas, load_sas, load_security
from obsw.frames.sdls_mac import HmacSha256, equal, hmac_sha256

try:
    import hmac as _hmac
    import os as _os
except ImportError:
    _hmac = None

SCID = 0x42
KEY = bytes(range(32))
KEY2 = bytes(range(100, 132))

# RFC 4231 test cases 1-7 (case 5 is truncated to 128 bits by the RFC)
RFC4231 = (
    (
        b"\x0b" * 20,
        b"Hi There",
        "b0344c61d8db38535ca8afceaf0bf12b881dc200c9833da726e9376c2e32cff7",
    ),
    (
        b"Jefe",
        b"what do ya want for nothing?",
        "5bdcc146bf60754e6a042426089575c75a003f089d2739839dec58b964ec3843",
    ),
    (
        b"\xaa" * 20,
        b"\xdd" * 50,
        "773ea91e36800e46854db8ebd09181a72959098b3ef8c122d9635514ced565fe",
    ),
    (
        bytes(range(1, 26)),
        b"\xcd" * 50,
        "82558a389a443c0ea4cc819899f2083a85f0faa3e578f8077a2e3ff46729665b",
    ),
    (b"\x0c" * 20, b"Test With Truncation", "a3b6167473100ee06e0c796c2955552b"),
    (
        b"\xaa" * 131,
        b"Test Using Larger Than Block-Size Key - Hash Key First",
        "60e431591ee0b67f0d8a26aacbf5b77f8e0bc6213728c5140546040f0ee37f54",
    ),
    (
        b"\xaa" * 131,
        b"This is a test using a larger than block-size key and a larger than block-size data."
        b" The key needs to be hashed before being used by the HMAC algorithm.",
        "9b09ffa71b942fcb27635fbcd5b0e944bfdc63644f0713938a7f51535c3a35e2",
    ),
)


def tc_packet(apid, payload):
    n = len(payload)
    return bytes((0x18 | apid >> 8, apid & 0xFF, 0xC0, 0, (n - 1) >> 8, (n - 1) & 0xFF)) + payload


def hexs(b):
    return "".join("%02x" % x for x in b)


class TestHmac(unittest.TestCase):
    def test_rfc4231_vectors(self):
        for key, msg, expected in RFC4231:
            self.assertEqual(hexs(hmac_sha256(key, msg))[: len(expected)], expected)

    def test_parts_are_concatenated(self):
        mac = HmacSha256(KEY)
        self.assertEqual(mac.digest(b"ab", b"", b"cd"), hmac_sha256(KEY, b"abcd"))

    @unittest.skipIf(_hmac is None, "CPython's hmac is the oracle")
    def test_same_as_cpython_hmac(self):
        import hashlib

        for n in (0, 1, 31, 63, 64, 65, 200):
            key = _os.urandom(n)
            msg = _os.urandom(n * 3 + 1)
            self.assertEqual(hmac_sha256(key, msg), _hmac.new(key, msg, hashlib.sha256).digest())

    def test_equal(self):
        self.assertTrue(equal(b"abc", b"abc"))
        self.assertFalse(equal(b"abc", b"abd"))
        self.assertFalse(equal(b"abc", b"ab"))
        self.assertTrue(equal(b"", b""))


class TestReplayWindow(unittest.TestCase):
    def test_edges(self):
        w = sdls.ReplayWindow(8, 8)
        self.assertFalse(w.acceptable(0))  # sequence numbers start at 1
        self.assertTrue(w.acceptable(1000))  # nothing accepted yet: any number from 1
        w.commit(1)
        self.assertFalse(w.acceptable(1))
        self.assertTrue(w.acceptable(9))  # top + ahead: the last one ahead
        self.assertFalse(w.acceptable(10))
        w = sdls.ReplayWindow(8, 8)
        w.commit(8)
        self.assertFalse(w.acceptable(8))
        self.assertTrue(w.acceptable(1))  # top - size + 1: the oldest one behind
        self.assertFalse(w.acceptable(0))
        w.commit(1)
        self.assertFalse(w.acceptable(1))
        self.assertTrue(w.acceptable(5))
        self.assertTrue(w.acceptable(16))
        self.assertFalse(w.acceptable(17))

    def test_without_ahead_any_jump_is_taken(self):
        w = sdls.ReplayWindow(8)
        w.commit(1)
        self.assertTrue(w.acceptable(1 << 40))
        w.commit(1 << 40)
        self.assertFalse(w.acceptable(1))
        self.assertTrue(w.acceptable((1 << 40) - 7))
        self.assertFalse(w.acceptable((1 << 40) - 8))

    def test_sliding_forgets_what_falls_out(self):
        w = sdls.ReplayWindow(4)
        for sn in (1, 2, 3):
            w.commit(sn)
        w.commit(6)
        self.assertFalse(w.acceptable(2))  # 6 - 2 = 4: out of the window
        self.assertTrue(w.acceptable(4))
        self.assertTrue(w.acceptable(5))
        self.assertFalse(w.acceptable(3))  # seen, and out of the window anyway
        w.commit(5)
        self.assertFalse(w.acceptable(5))
        self.assertFalse(w.acceptable(6))

    def test_size_bounds(self):
        self.assertRaises(sdls.SdlsError, sdls.ReplayWindow, 0)
        self.assertRaises(sdls.SdlsError, sdls.ReplayWindow, sdls.MAX_WINDOW + 1)
        self.assertRaises(sdls.SdlsError, sdls.ReplayWindow, 8, 0)


class TestSecurityAssociation(unittest.TestCase):
    def test_states(self):
        sa = sdls.SecurityAssociation(5, 0)
        self.assertEqual(sa.state, sdls.SA_UNKEYED)
        self.assertRaises(sdls.SdlsError, sa.start)
        sa.set_key(KEY)
        self.assertEqual(sa.state, sdls.SA_KEYED)
        sa.start()
        self.assertEqual(sa.state, sdls.SA_OPERATIONAL)
        sa.stop()
        self.assertEqual(sa.state, sdls.SA_KEYED)
        sa.expire()
        self.assertEqual(sa.state, sdls.SA_EXPIRED)
        self.assertIsNone(sa.key)
        self.assertRaises(sdls.SdlsError, sa.set_key, KEY)
        self.assertRaises(sdls.SdlsError, sa.start)

    def test_bad_parameters(self):
        for kw in (
            {"spi": 0},
            {"spi": 0xFFFF},
            {"vcid": 64},
            {"map_id": 64},
            {"mac_length": 7},
            {"mac_length": 33},
            {"sn_length": 0},
            {"window": 0},
        ):
            args = {"spi": 1, "vcid": 0, "key": KEY}
            args.update(kw)
            self.assertRaises(sdls.SdlsError, sdls.SecurityAssociation, **args)
        self.assertRaises(sdls.SdlsError, sdls.SecurityAssociation, 1, 0, b"short")


def security(**kw):
    return sdls.TcSecurity(
        [
            sdls.SecurityAssociation(1, 0, KEY, **kw),
            sdls.SecurityAssociation(2, 0, KEY2, map_id=63),
        ]
    )


class Rig:
    """A ground TcSecurity signing and a frame processor verifying, with its own SA copies."""

    def __init__(self, **kw):
        self.ground = security(**kw)
        self.onboard = security(**kw)
        self.routed = []
        self.essential = []
        self.rejected = []
        self.p = processor.FrameProcessor(
            SCID,
            lambda apid, pkt: self.routed.append(pkt),
            self.essential.append,
            essential_map=63,
            security=self.onboard,
        )
        self.p.rejected_listeners.append(lambda *a: self.rejected.append(a))

    def frame(self, packet, seq=0, map_id=1, bypass=True, sign=True, vcid=0):
        data = tc.Segment(map_id, packet).pack()
        if sign:
            data = self.ground.apply(SCID, vcid, data, bypass)
        return tc.TcFrame(SCID, vcid, data, seq, bypass).pack()

    def send(self, frame, link=0, now=0.0):
        self.p.receive(link, cltu.encode(frame), now)


class TestTcSecurity(unittest.TestCase):
    def test_layout(self):
        r = Rig()
        pkt = tc_packet(0x21, b"cmd")
        raw = r.frame(pkt, seq=7, bypass=False)
        sa = r.ground.sas[1]
        self.assertEqual(len(raw), 5 + 1 + 2 + 4 + len(pkt) + 16 + 2)
        self.assertEqual(tc.frame_length(raw), len(raw))  # the length covers header and trailer
        f = tc.TcFrame.unpack(raw)  # and the FECF the whole frame
        self.assertEqual(f.data[:7], b"\xc1\x00\x01\x00\x00\x00\x01")  # MAP 1, SPI 1, SN 1
        self.assertEqual(f.data[7 : 7 + len(pkt)], pkt)
        masked = raw[:4] + b"\x00"
        self.assertEqual(f.data[-16:], hmac_sha256(KEY, masked + f.data[:-16])[:16])
        self.assertEqual(sa.sn_sent, 1)

    def test_signed_frame_accepted(self):
        r = Rig()
        pkt = tc_packet(0x21, b"cmd")
        r.send(r.frame(pkt))
        self.assertEqual(r.routed, [pkt])
        self.assertEqual(r.rejected, [])
        self.assertEqual(r.onboard.counters["ok"], 1)

    def test_ad_frames_through_farm(self):
        r = Rig()
        for seq in range(3):
            r.send(r.frame(tc_packet(0x21, b"%d" % seq), seq=seq, bypass=False))
        self.assertEqual(len(r.routed), 3)
        self.assertEqual(r.p.farms[0].vr, 3)

    def test_forged_frame_rejected(self):
        r = Rig()
        data = bytearray(tc.TcFrame.unpack(r.frame(tc_packet(0x21, b"cmd"))).data)
        data[8] ^= 0x01  # one bit of the packet, in a frame with a good FECF
        r.send(tc.TcFrame(SCID, 0, bytes(data), 0, True).pack())
        self.assertEqual(r.routed, [])
        self.assertEqual(r.rejected, [(sdls.BAD_MAC, 0, 1, 0)])
        self.assertEqual(r.onboard.counters["bad_mac"], 1)
        self.assertEqual(r.p.counters["tc_rejected"], 1)

    def test_wrong_key_rejected(self):
        r = Rig()
        r.ground.sas[1] = sdls.SecurityAssociation(1, 0, KEY2)
        r.send(r.frame(tc_packet(0x21, b"cmd")))
        self.assertEqual(r.rejected[0][0], sdls.BAD_MAC)

    def test_header_is_authenticated(self):
        r = Rig()
        raw = r.frame(tc_packet(0x21, b"cmd"), bypass=False)
        f = tc.TcFrame.unpack(raw)
        r.send(tc.TcFrame(SCID, 0, f.data, 0, True).pack())  # AD made BD: the MAC says no
        self.assertEqual(r.rejected[0][0], sdls.BAD_MAC)

    def test_replayed_frame_rejected(self):
        r = Rig()
        frame = r.frame(tc_packet(0x21, b"cmd"))
        r.send(frame)
        r.send(frame)  # same link: not a redundant copy, a replay
        self.assertEqual(len(r.routed), 1)
        self.assertEqual(r.rejected, [(sdls.REPLAY, 0, 1, 1)])

    def test_out_of_window_rejected(self):
        r = Rig(window=4, ahead=4)
        r.send(r.frame(tc_packet(0x21, b"cmd")))
        r.ground.sas[1].sn_sent = 10
        r.send(r.frame(tc_packet(0x21, b"cmd")))
        self.assertEqual(r.rejected, [(sdls.REPLAY, 0, 1, 11)])

    def test_fresh_receiver_takes_up_the_senders_numbers(self):
        r = Rig(window=4)
        r.ground.sas[1].sn_sent = 500  # the receiver restarted without its state
        r.send(r.frame(tc_packet(0x21, b"cmd")))
        self.assertEqual(len(r.routed), 1)
        self.assertEqual(r.onboard.sas[1].window.top, 501)

    def test_older_in_window_accepted_once(self):
        r = Rig()
        first = r.frame(tc_packet(0x21, b"1"))
        second = r.frame(tc_packet(0x21, b"2"))
        r.send(second)
        r.send(first)
        r.send(first)
        self.assertEqual(len(r.routed), 2)
        self.assertEqual([x[0] for x in r.rejected], [sdls.REPLAY])

    def test_unsigned_frame_rejected(self):
        r = Rig()
        r.send(r.frame(tc_packet(0x21, b"cmd"), sign=False))
        self.assertEqual(r.routed, [])
        self.assertEqual(len(r.rejected), 1)
        self.assertIn(r.rejected[0][0], (sdls.BAD_SPI, sdls.TOO_SHORT))

    def test_tiny_frame_too_short(self):
        r = Rig()
        r.send(tc.TcFrame(SCID, 0, b"\x01", 0, True).pack())
        self.assertEqual(r.rejected[0][0], sdls.TOO_SHORT)
        r.send(tc.TcFrame(SCID, 0, b"\x01\x00\x01abc", 0, True).pack())  # SPI 1, no room
        self.assertEqual(r.rejected[1][0], sdls.TOO_SHORT)

    def test_bad_spi(self):
        r = Rig()
        r.ground.sas[1].spi = 9
        r.ground.sas[9] = r.ground.sas.pop(1)
        r.send(r.frame(tc_packet(0x21, b"cmd")))
        self.assertEqual(r.rejected, [(sdls.BAD_SPI, 0, 9, 0)])

    def test_map_sa_only_for_its_map(self):
        r = Rig()
        # the essential MAP's SA on an ordinary MAP, the VC's SA on the essential MAP
        data = r.ground.apply(SCID, 0, tc.Segment(1, b"abc").pack(), True, r.ground.sas[1])
        wrong = bytearray(data)
        wrong[0] = 63  # MAP 63 with SPI 1
        r.send(tc.TcFrame(SCID, 0, bytes(wrong), 0, True).pack())
        self.assertEqual(r.rejected[-1][0], sdls.BAD_SPI)
        self.assertRaises(
            sdls.SdlsError,
            r.ground.apply,
            SCID,
            0,
            tc.Segment(1, b"a").pack(),
            True,
            r.ground.sas[2],
        )

    def test_essential_map_signed_with_its_own_sa(self):
        r = Rig()
        r.send(r.frame(b"\x04\x00", map_id=63))
        self.assertEqual(r.essential, [b"\x04\x00"])
        self.assertEqual(r.ground.sas[2].sn_sent, 1)
        self.assertEqual(r.ground.sas[1].sn_sent, 0)

    def test_sa_not_operational(self):
        r = Rig()
        frame = r.frame(tc_packet(0x21, b"cmd"))
        r.onboard.sas[1].stop()
        r.send(frame)
        r.onboard.sas[1].start()
        r.send(frame)
        r.onboard.sas[1].expire()
        r.send(r.frame(tc_packet(0x21, b"two")))
        self.assertEqual([x[0] for x in r.rejected], [sdls.NOT_OPERATIONAL, sdls.NOT_OPERATIONAL])
        self.assertEqual(len(r.routed), 1)

    def test_sender_needs_operational_sa(self):
        r = Rig()
        r.ground.sas[1].stop()
        self.assertRaises(sdls.SdlsError, r.frame, tc_packet(0x21, b"cmd"))

    def test_channel_without_sa_is_not_secured_but_rejected(self):
        r = Rig()
        r.p = processor.FrameProcessor(
            SCID, lambda a, p: r.routed.append(p), tc_vcids=(0, 1), security=r.onboard
        )
        r.p.rejected_listeners.append(lambda *a: r.rejected.append(a))
        self.assertRaises(sdls.SdlsError, r.frame, tc_packet(0x21, b"cmd"), vcid=1)
        r.send(r.frame(tc_packet(0x21, b"cmd"), vcid=1, sign=False))  # VC 1 has no SA
        self.assertEqual(r.routed, [])
        self.assertEqual(r.rejected[0][0], sdls.BAD_SPI)

    def test_control_commands_pass(self):
        r = Rig()
        r.send(tc.TcFrame(SCID, 0, tc.UNLOCK, 0, True, True).pack())
        self.assertEqual(r.rejected, [])
        self.assertEqual(r.p.counters["accepted"], 1)

    def test_farm_discard_does_not_burn_the_sequence_number(self):
        r = Rig()
        ahead = r.frame(tc_packet(0x21, b"late"), seq=1, bypass=False)
        r.send(ahead)  # N(S) 1 while V(R) is 0: FARM-1 discards it
        self.assertEqual(r.routed, [])
        r.send(r.frame(tc_packet(0x21, b"first"), seq=0, bypass=False))
        r.send(ahead)  # FOP-1 retransmits the very same frame
        self.assertEqual(len(r.routed), 2)
        self.assertEqual(r.rejected, [])

    def test_context_survives_restart(self):
        r = Rig()
        frame = r.frame(tc_packet(0x21, b"cmd"))
        r.send(frame)
        ctx = r.onboard.context()
        fresh = security()
        fresh.restore(ctx)
        self.assertFalse(fresh.sas[1].window.acceptable(1))
        self.assertTrue(fresh.sas[1].window.acceptable(2))
        ground = security()
        ground.restore(r.ground.context())
        self.assertEqual(ground.sas[1].sn_sent, 1)

    def test_exhausted_sequence_numbers(self):
        r = Rig(sn_length=1)
        r.ground.sas[1].sn_sent = 255
        self.assertRaises(sdls.SdlsError, r.frame, tc_packet(0x21, b"cmd"))

    def test_too_long_refused_without_using_a_number(self):
        r = Rig()
        self.assertRaises(sdls.SdlsError, r.frame, bytes(1024 - 5 - 1 - 6 - 16 - 2 + 1))
        self.assertEqual(r.ground.sas[1].sn_sent, 0)
        r.frame(bytes(1024 - 5 - 1 - 6 - 16 - 2))
        self.assertEqual(r.ground.sas[1].sn_sent, 1)


class TestEssentialCommands(unittest.TestCase):
    """The reconfiguration module's HPCs are authenticated with the essential MAP's own SA."""

    def setUp(self):
        from obsw.reconfig import essential as E

        self.E = E
        self.ground = security()
        self.unit = E.Essential(SCID, security=security())

    def hpc_frame(self, hpc, sign=True, map_id=63):
        data = tc.Segment(map_id, hpc.packet()).pack()
        if sign:
            data = self.ground.apply(SCID, 0, data, True)
        return cltu.encode(tc.TcFrame(SCID, 0, data, 0, True).pack())

    def test_signed_executed_others_rejected(self):
        E = self.E
        hpc = E.Hpc(E.HPC_LINES, (0x3, 0x1), E.TARGET_BOTH)
        self.unit.feed(self.hpc_frame(hpc), 0.0)
        self.assertEqual(self.unit.counters["hpcs"], 1)
        self.assertEqual(self.ground.sas[2].sn_sent, 1)  # the essential MAP's SA
        self.unit.feed(self.hpc_frame(hpc), 0.0)  # a new SN: executed again
        self.assertEqual(self.unit.counters["hpcs"], 2)
        replay = self.hpc_frame(hpc)
        self.unit.feed(replay, 0.0)
        self.unit.feed(replay, 0.0)
        self.unit.feed(self.hpc_frame(hpc, sign=False), 0.0)
        self.assertEqual(self.unit.counters["hpcs"], 3)
        c = self.unit.frames.security.counters
        self.assertEqual((c["ok"], c["replay"], c["bad_spi"]), (3, 1, 1))
        self.assertEqual(self.unit.frames.counters["tc_rejected"], 2)

    def test_security_from_file(self):
        import os

        said = []
        # secure by default: no key file, no SA, every essential TC refused (one line said)
        missing = self.E.security_from_file("/nonexistent/tc.keys", None, said.append)
        self.assertEqual(missing.sas, {})
        unit = self.E.Essential(SCID, security=missing)
        unit.feed(self.hpc_frame(self.E.Hpc(self.E.HPC_REPORT, ())), 0.0)
        unit.feed(self.hpc_frame(self.E.Hpc(self.E.HPC_REPORT, ()), sign=False), 0.0)
        self.assertEqual(unit.counters["hpcs"], 0)
        self.assertEqual(len(said), 1)
        try:  # a host's temporary folder, else (a board) the root of its filesystem
            os.stat("/tmp")
            path = "/tmp/obsw_test_frames_sdls_bad.keys"
        except OSError:
            path = "/obsw_test_frames_sdls_bad.keys"
        # unauthenticated only when the mission put its marker file there, and then said so
        with open(path + ".insecure", "w") as f:
            f.write("")
        try:
            off = self.E.security_from_file(
                "/nonexistent/tc.keys", path + ".insecure", said.append
            )
        finally:
            os.remove(path + ".insecure")
        self.assertIsNone(off)
        self.assertIn("OFF", said[-1])
        with open(path, "w") as f:
            f.write("{not a key file")
        try:
            broken = self.E.security_from_file(path, None, said.append)
        finally:
            os.remove(path)
        self.assertEqual(broken.sas, {})  # fail secure, keep running
        unit = self.E.Essential(SCID, security=broken)
        unit.feed(self.hpc_frame(self.E.Hpc(self.E.HPC_REPORT, ())), 0.0)
        self.assertEqual(unit.counters["hpcs"], 0)
        self.assertEqual(broken.counters["bad_spi"], 1)


class TestKeyFile(unittest.TestCase):
    def test_round_trip(self):
        sas = security(mac_length=12, window=32, ahead=100).sas
        text = dump_sas([sas[1], sas[2]])
        back = load_sas(text)
        self.assertEqual([(s.spi, s.vcid, s.map_id) for s in back], [(1, 0, None), (2, 0, 63)])
        self.assertEqual(back[0].key, KEY)
        self.assertEqual(back[0].mac_length, 12)
        self.assertEqual(back[0].window.size, 32)
        self.assertEqual(back[0].window.ahead, 100)
        self.assertIsNone(back[1].window.ahead)
        self.assertEqual(back[1].state, sdls.SA_OPERATIONAL)
        self.assertEqual(len(load_security(text).sas), 2)

    def test_errors(self):
        good = '{"format": "obsw-sdls-keys", "version": 1, "sas": [%s]}'
        sa = '{"spi": 1, "vcid": 0, "key": "%s"%s}'
        k = hexs(KEY)
        for text in (
            "not json",
            "[]",
            '{"format": "x", "version": 1, "sas": []}',
            '{"format": "obsw-sdls-keys", "version": 2, "sas": []}',
            '{"format": "obsw-sdls-keys", "version": 1}',
            good % "3",
            good % (sa % ("zz", "")),
            good % (sa % ("00", "")),
            good % (sa % (k, ', "state": "sleepy"')),
            good % (sa % (k, ', "spi2": 3')),
            good % (sa % (k, ', "window": "big"')),
            good % (sa % (k, ', "mac_length": 99')),
            good % ((sa % (k, "")) + ", " + (sa % (k, ""))),
        ):
            self.assertRaises(KeyFileError, load_security, text)

    def test_expired_needs_no_key(self):
        text = '{"format": "obsw-sdls-keys", "version": 1, "sas": [%s]}' % (
            '{"spi": 3, "vcid": 1, "state": "expired"}'
        )
        self.assertEqual(load_sas(text)[0].state, sdls.SA_EXPIRED)


if __name__ == "__main__":
    unittest.main()
