"""SDLS extended procedures: OTAR under a master key, key activation, verification, SA
stop/expire/rekey/start, status and ARSN; refusals answered, never raised; state saved."""

import unittest

from obsw.frames import sdls, tc
from obsw.frames import sdls_ep as ep
from obsw.frames.gcm import AesGcm
from obsw.frames.sdls_gcm import GcmSecurityAssociation

MASTER = bytes(range(32))
OLD = bytes(range(32, 64))
NEW = bytes(range(64, 96))
SCID = 0x2A


def rig():
    store = ep.KeyStore()
    store.add(1, MASTER, ep.ACTIVE)
    sa = GcmSecurityAssociation(1, 0, OLD)
    security = sdls.TcSecurity([sa], segment_header=True)
    engine = ep.ExtendedProcedures(store, security)
    saved = []
    engine.on_change = lambda: saved.append(store.dump())
    return engine, sa, security, saved


def replies(engine, *pdus):
    return [(tag, v[0], v[1:]) for tag, v in ep.split(engine.handle(b"".join(pdus)))]


def frame(security, key_sa_spi=1):
    data = security.apply(SCID, 0, tc.Segment(1, b"\x18\x01\xc0\x00\x00\x00\x07").pack())
    return tc.TcFrame(SCID, 0, data, 0).pack()


class TestProcedures(unittest.TestCase):
    def test_otar_activate_verify_rekey_start(self):
        engine, sa, security, saved = rig()
        sender = sdls.TcSecurity([GcmSecurityAssociation(1, 0, OLD)], True)
        old_frame = frame(sender)
        upload = ep.otar_pdu(1, MASTER, {200: NEW}, bytes(12))
        got = replies(engine, upload, ep.pdu(ep.KEY_ACTIVATE, b"\x00\xc8"))
        self.assertEqual(got, [(ep.OTAR | 0x80, ep.DONE, b""), (0x82, ep.DONE, b"")])
        self.assertEqual(engine.store.keys[200], [ep.ACTIVE, NEW])
        challenge = bytes(range(16))
        ((tag, status, data),) = replies(engine, ep.pdu(ep.KEY_VERIFY, b"\x00\xc8" + challenge))
        self.assertEqual(status, ep.DONE)
        self.assertTrue(ep.verify_reply_ok({200: NEW}, data, {200: challenge}))
        self.assertFalse(ep.verify_reply_ok({200: OLD}, data, {200: challenge}))
        # rekey needs the SA unkeyed: stop, expire, rekey, start
        spi = b"\x00\x01"
        got = replies(
            engine,
            ep.pdu(ep.SA_REKEY, spi + b"\x00\xc8"),
            ep.pdu(ep.SA_STOP, spi),
            ep.pdu(ep.SA_EXPIRE, spi),
            ep.pdu(ep.SA_REKEY, spi + b"\x00\xc8"),
            ep.pdu(ep.SA_START, spi),
            ep.pdu(ep.SA_STATUS, spi),
        )
        self.assertEqual([g[1] for g in got], [ep.SA_STATE] + [ep.DONE] * 5)
        self.assertEqual(got[-1][2], spi + bytes((sdls.SA_OPERATIONAL,)))
        self.assertEqual(sa.key, NEW)
        # frames under the old key are refused, under the new one taken
        self.assertEqual(security.process(old_frame, len(old_frame))[0], sdls.BAD_MAC)
        new_frame = frame(sdls.TcSecurity([GcmSecurityAssociation(1, 0, NEW)], True))
        outcome, got_sa, sn, _ = security.process(new_frame, len(new_frame))
        self.assertEqual(outcome, sdls.OK)
        security.commit(got_sa, sn)
        ((tag, status, data),) = replies(engine, ep.pdu(ep.SA_READ_ARSN, spi))
        self.assertEqual(data, spi + (1).to_bytes(12, "big"))
        self.assertTrue(saved)
        self.assertEqual(ep.KeyStore.load(saved[-1]).keys, engine.store.keys)
        lines = ep.describe(engine.handle(ep.pdu(ep.KEY_INVENTORY, b"\x00\x00\xff\xff")))
        self.assertEqual(lines, ["inventory: done 1:active 200:active"])

    def test_refusals(self):
        engine, sa, security, saved = rig()
        wrong = ep.otar_pdu(1, OLD, {201: NEW}, bytes(12))  # not the master key
        master_id = ep.otar_pdu(1, MASTER, {5: NEW}, bytes(12))  # IDs below 128 are masters
        unknown_master = ep.otar_pdu(9, MASTER, {201: NEW}, bytes(12))
        got = replies(
            engine,
            wrong,
            master_id,
            unknown_master,
            ep.pdu(ep.KEY_ACTIVATE, b"\x00\xc9"),
            ep.pdu(ep.SA_START, b"\x00\x07"),
            ep.pdu(ep.SA_START, b"\x00\x01"),
            ep.pdu(0x3A, b""),
            ep.pdu(ep.SA_STATUS, b""),
        )
        self.assertEqual(
            [g[1] for g in got],
            [ep.BAD_MAC, ep.KEY_STATE, ep.UNKNOWN_KEY, ep.UNKNOWN_KEY, ep.UNKNOWN_SA,
             ep.SA_STATE, ep.UNKNOWN_PROCEDURE, ep.BAD_PDU],
        )  # fmt: skip
        self.assertEqual(saved, [])
        self.assertEqual(engine.counters, {"done": 0, "refused": 8})
        self.assertEqual(sa.state, sdls.SA_OPERATIONAL)

    def test_a_key_in_use_cannot_be_destroyed(self):
        engine, sa, security, saved = rig()
        engine.store.add(300, OLD, ep.ACTIVE)
        ((tag, status, data),) = replies(engine, ep.pdu(ep.KEY_DESTROY, b"\x01\x2c"))
        self.assertEqual(status, ep.KEY_STATE)

    def test_garbage_never_raises(self):
        engine, sa, security, saved = rig()
        seed = 12345
        for n in range(200):
            seed = (seed * 1103515245 + 12345) & 0x7FFFFFFF
            buf = bytes((seed >> (i % 23)) & 0xFF for i in range(n % 40))
            out = engine.handle(buf)
            self.assertTrue(len(out) >= 4 or buf == b"")

    def test_otar_wraps_with_gcm_under_the_master_key(self):
        upload = ep.otar_pdu(1, MASTER, {200: NEW}, bytes(12))
        ((tag, v),) = ep.split(upload)
        clear = AesGcm(MASTER).decrypt(v[2:14], v[14:-16], v[-16:], v[0:2])
        self.assertEqual(clear, b"\x00\xc8" + NEW)


if __name__ == "__main__":
    unittest.main()
