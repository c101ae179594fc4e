"""CFDP class 1 (unacknowledged) procedures over a simulated link."""

import unittest

from cfdp_sim import Link, make_pair, payload
from obsw.cfdp.defs import (
    CHECK_LIMIT_REACHED,
    DATA_COMPLETE,
    FILE_CHECKSUM_FAILURE,
    FILE_RETAINED,
    FILE_STATUS_UNREPORTED,
    NO_ERROR,
    UNACKNOWLEDGED,
)
from obsw.crc import (
    CHECKSUM_CRC32,
    CHECKSUM_CRC32C,
    CHECKSUM_MODULAR,
    CHECKSUM_NULL,
    CHECKSUM_PROXIMITY1,
)

DATA = payload(1500)


def transfer(closure=True, checksum=CHECKSUM_CRC32, data=DATA, **link_kw):
    a, b = make_pair(files_a={"src.bin": data}, mode=UNACKNOWLEDGED)
    a.put(2, "src.bin", "dst.bin", closure=closure, checksum=checksum)
    link = Link(a, b, **link_kw)
    link.run()
    return a, b, link


class TestClass1(unittest.TestCase):
    def test_every_checksum_type(self):
        for ck in (
            CHECKSUM_MODULAR,
            CHECKSUM_PROXIMITY1,
            CHECKSUM_CRC32C,
            CHECKSUM_CRC32,
            CHECKSUM_NULL,
        ):
            a, b, link = transfer(checksum=ck)
            self.assertEqual(bytes(b.fs.files["dst.bin"]), DATA)
            fin = link.finished(0)[0].info
            self.assertEqual(fin["condition"], NO_ERROR)
            self.assertEqual(fin["file_status"], FILE_RETAINED)

    def test_without_closure_sender_finishes_after_eof(self):
        a, b, link = transfer(closure=False)
        self.assertEqual(bytes(b.fs.files["dst.bin"]), DATA)
        fin = link.finished(0)[0].info
        self.assertEqual((fin["condition"], fin["delivery"]), (NO_ERROR, DATA_COMPLETE))
        self.assertEqual(fin["file_status"], FILE_STATUS_UNREPORTED)
        self.assertEqual(link.finished(1)[0].info["condition"], NO_ERROR)
        self.assertEqual(a.tx, {})
        self.assertEqual(b.tx, {})

    def test_duplicates_and_reordering(self):
        a, b, link = transfer(seed=4, dup=0.2, reorder=0.3)
        self.assertEqual(bytes(b.fs.files["dst.bin"]), DATA)
        self.assertEqual(link.finished(1)[0].info["condition"], NO_ERROR)

    def test_empty_file(self):
        a, b, link = transfer(data=b"")
        self.assertEqual(bytes(b.fs.files["dst.bin"]), b"")
        self.assertEqual(link.finished(0)[0].info["condition"], NO_ERROR)

    def test_loss_reaches_check_limit(self):
        # class 1 cannot recover lost data: the check timer runs out and the receiver cancels
        n = [0]

        def drop(side, pdu):
            n[0] += 1
            return side == 0 and n[0] == 5

        a, b, link = transfer(drop=drop)
        fin = link.finished(1)[0].info
        self.assertEqual(fin["condition"], CHECK_LIMIT_REACHED)
        self.assertFalse("dst.bin" in b.fs.files)
        self.assertEqual(link.finished(0)[0].info["condition"], CHECK_LIMIT_REACHED)

    def test_corrupted_data_fails_checksum(self):
        # flip a data octet but keep the PDU well-formed (no CRC on this link)
        hit = [False]

        def drop(side, pdu):
            return False

        a, b = make_pair(files_a={"src.bin": DATA}, mode=UNACKNOWLEDGED)
        a.put(2, "src.bin", "dst.bin", closure=True)
        link = Link(a, b, drop=drop)
        orig = b.receive

        def receive(pdu, now):
            if not hit[0] and len(pdu) > 40 and pdu[0] & 0x10:
                hit[0] = True
                pdu = pdu[:-1] + bytes((pdu[-1] ^ 0xFF,))
            return orig(pdu, now)

        b.receive = receive
        link.run()
        self.assertEqual(link.finished(1)[0].info["condition"], FILE_CHECKSUM_FAILURE)
        self.assertFalse("dst.bin" in b.fs.files)

    def test_crc_protected_pdus_drop_corruption(self):
        a, b = make_pair(files_a={"src.bin": DATA}, mode=UNACKNOWLEDGED, crc=True)
        a.put(2, "src.bin", "dst.bin", closure=True)
        link = Link(a, b, seed=9, corrupt=0.05)
        link.run()
        self.assertTrue(b.stats["decode_errors"] > 0)
        conds = [i.info["condition"] for i in link.finished(1)]
        # either the corrupted PDUs were only directives' repeats, or the check limit caught it
        self.assertTrue(conds[0] in (NO_ERROR, CHECK_LIMIT_REACHED))


if __name__ == "__main__":
    unittest.main()


class TestFileDataFastPath(unittest.TestCase):
    """The receiving entity takes file data PDUs whose header repeats the last one's straight
    to their transaction; anything else goes the whole way (decoded, checked, routed)."""

    def pdus(self):
        a, b = make_pair(files_a={"src.bin": DATA}, mode=UNACKNOWLEDGED)
        a.put(2, "src.bin", "dst.bin")
        out = []
        for _ in range(100):
            sent = a.transmit(0.0)
            if not sent:
                break
            out += [p for _, p in sent]
        return b, out

    def test_every_pdu_counted_and_the_file_whole(self):
        b, pdus = self.pdus()
        for p in pdus:
            b.receive(p, 0.0)
        self.assertEqual(b.stats["pdus_received"], len(pdus))
        self.assertEqual(bytes(b.fs.files["dst.bin"]), DATA)

    def test_another_destination_is_misrouted_after_the_fast_path_began(self):
        b, pdus = self.pdus()
        for p in pdus[:3]:  # metadata, then two file data PDUs: the fast path is set
            b.receive(p, 0.0)
        wrong = bytearray(pdus[3])
        eid, seq = ((wrong[3] >> 4) & 7) + 1, (wrong[3] & 7) + 1
        wrong[4 + eid + seq + eid - 1] = 9  # the destination entity id: not this entity's
        b.receive(bytes(wrong), 0.0)
        self.assertEqual(b.stats["misrouted"], 1)
        self.assertEqual(b.stats["pdus_received"], 4)

    def test_a_short_pdu_is_a_decode_error_not_a_write(self):
        b, pdus = self.pdus()
        for p in pdus[:3]:
            b.receive(p, 0.0)
        before = bytes(b.fs.files[list(b.fs.files)[0]])
        b.receive(pdus[3][:-5], 0.0)  # its length field says more than came
        self.assertEqual(b.stats["decode_errors"], 1)
        self.assertEqual(bytes(b.fs.files[list(b.fs.files)[0]]), before)

    def test_pdus_shorter_than_a_header_are_decode_errors(self):
        b, pdus = self.pdus()
        for p in pdus[:3]:
            b.receive(p, 0.0)
        for n in range(4):  # the first octets of a file data PDU, the fast path set
            self.assertIsNone(b.receive(pdus[3][:n], 0.0))
        self.assertEqual(b.stats["decode_errors"], 4)
