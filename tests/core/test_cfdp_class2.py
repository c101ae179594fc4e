"""CFDP class 2 (acknowledged) procedures over a lossy simulated link."""

import unittest

from cfdp_sim import Link, ack_of, directive, make_pair, payload
from obsw.cfdp.defs import (
    ACKNOWLEDGED,
    DATA_COMPLETE,
    FILE_RETAINED,
    NO_ERROR,
    PROMPT_KEEP_ALIVE,
    PROMPT_NAK,
)
from obsw.crc import CHECKSUM_CRC32C, CHECKSUM_MODULAR, CHECKSUM_NULL, CHECKSUM_PROXIMITY1

DATA = payload(4000)


def transfer(data=DATA, put_kw=None, pair_kw=None, **link_kw):
    a, b = make_pair(files_a={"src.bin": data}, mode=ACKNOWLEDGED, **(pair_kw or {}))
    tid = a.put(2, "src.bin", "dst.bin", **(put_kw or {}))
    link = Link(a, b, **link_kw)
    done = link.run()
    return a, b, link, tid, done


class TestClass2(unittest.TestCase):
    def check_ok(self, a, b, link, data=DATA):
        self.assertEqual(bytes(b.fs.files["dst.bin"]), data)
        s = link.finished(0)[0].info
        r = link.finished(1)[0].info
        for f in (s, r):
            self.assertEqual(f["condition"], NO_ERROR)
            self.assertEqual(f["delivery"], DATA_COMPLETE)
            self.assertEqual(f["file_status"], FILE_RETAINED)
        self.assertEqual(a.tx, {})
        self.assertEqual(b.tx, {})

    def test_lossless(self):
        a, b, link, tid, done = transfer()
        self.assertTrue(done)
        self.check_ok(a, b, link)
        self.assertEqual(a.stats["retransmitted_pdus"], 0)

    def test_loss_both_directions_many_seeds(self):
        for seed in range(1, 9):
            a, b, link, tid, done = transfer(seed=seed, loss=0.15)
            self.assertTrue(done)
            self.check_ok(a, b, link)

    def test_loss_duplication_reordering(self):
        for seed in (11, 12, 13):
            a, b, link, tid, done = transfer(seed=seed, loss=0.1, dup=0.1, reorder=0.2)
            self.assertTrue(done)
            self.check_ok(a, b, link)

    def test_corruption_with_crc(self):
        for seed in (21, 22):
            a, b, link, tid, done = transfer(seed=seed, corrupt=0.1, pair_kw={"crc": True})
            self.assertTrue(done)
            self.check_ok(a, b, link)
            self.assertTrue(a.stats["decode_errors"] + b.stats["decode_errors"] > 0)

    def test_deferred_nak_mode(self):
        a, b, link, tid, done = transfer(seed=3, loss=0.2, pair_kw={"immediate_nak": False})
        self.assertTrue(done)
        self.check_ok(a, b, link)

    def test_checksum_types(self):
        for ck in (CHECKSUM_MODULAR, CHECKSUM_PROXIMITY1, CHECKSUM_CRC32C, CHECKSUM_NULL):
            a, b, link, tid, done = transfer(seed=5, loss=0.1, put_kw={"checksum": ck})
            self.check_ok(a, b, link)

    def test_lost_metadata_is_requested(self):
        first = [True]

        def drop(side, pdu):
            if side == 0 and first[0] and directive(pdu) == 0x07:
                first[0] = False
                return True
            return False

        a, b, link, tid, done = transfer(drop=drop)
        self.assertFalse(first[0])
        self.check_ok(a, b, link)

    def test_lost_eof_and_acks(self):
        # drop the first EOF, the first ACK(EOF), the first Finished and the first ACK(Finished)
        seen = set()

        def drop(side, pdu):
            code = directive(pdu)
            if code is None:
                return False
            key = (side, code, ack_of(pdu) if code == 6 else 0)
            if key in seen:
                return False
            seen.add(key)
            return code in (4, 5, 6)

        a, b, link, tid, done = transfer(drop=drop)
        self.assertTrue(done)
        self.check_ok(a, b, link)
        self.assertTrue(a.stats["eof_resent"] >= 1)
        self.assertTrue(b.stats["finished_resent"] >= 1)

    def test_retransmissions_close_to_losses(self):
        a, b, link, tid, done = transfer(data=payload(64 * 300), seed=8, loss=0.05)
        self.check_ok(a, b, link, payload(64 * 300))
        lost_fd = link.dropped[0]
        self.assertTrue(a.stats["retransmitted_pdus"] <= lost_fd * 1.5 + 2)

    def test_large_file_mode(self):
        a, b, link, tid, done = transfer(seed=2, loss=0.1, pair_kw={"large": True})
        self.check_ok(a, b, link)

    def test_prompt_nak_and_keep_alive(self):
        a, b = make_pair(files_a={"src.bin": DATA}, mode=ACKNOWLEDGED)
        tid = a.put(2, "src.bin", "dst.bin")
        link = Link(a, b, drop=lambda side, pdu: side == 0 and bool(pdu[0] & 0x10) and pdu[-1] & 1)
        for _ in range(3):
            link.step()
        self.assertTrue(a.prompt(tid, PROMPT_KEEP_ALIVE, link.now))
        self.assertTrue(a.prompt(tid, PROMPT_NAK, link.now))
        link.step()
        link.step()
        sender = a.find(tid)
        self.assertTrue(sender.peer_progress >= 0)
        self.assertTrue(b.stats["naks_sent"] >= 1)
        link.drop = None
        link.run()
        self.check_ok(a, b, link)

    def test_periodic_keep_alive(self):
        a, b, link, tid, done = transfer(seed=4, loss=0.3, pair_kw={"keep_alive_interval": 1.0})
        self.check_ok(a, b, link)

    def test_two_transfers_at_once_both_ways(self):
        a, b = make_pair(
            files_a={"x": DATA}, files_b={"y": bytes(reversed(DATA))}, mode=ACKNOWLEDGED
        )
        a.put(2, "x", "x2")
        b.put(1, "y", "y2")
        a.put(2, "x", "x3")
        link = Link(a, b, seed=6, loss=0.1)
        self.assertTrue(link.run())
        self.assertEqual(bytes(b.fs.files["x2"]), DATA)
        self.assertEqual(bytes(b.fs.files["x3"]), DATA)
        self.assertEqual(bytes(a.fs.files["y2"]), bytes(reversed(DATA)))


if __name__ == "__main__":
    unittest.main()
