"""CFDP fault handling: every condition code path, cancel, suspend, resume, abandon, report."""

import unittest

from cfdp_sim import Link, directive, make_pair, payload
from obsw.cfdp.defs import (
    ACKNOWLEDGED,
    CANCEL_REQUEST_RECEIVED,
    DATA_INCOMPLETE,
    FILE_CHECKSUM_FAILURE,
    FILE_DATA,
    FILE_DISCARDED,
    FILE_RETAINED,
    FILE_SIZE_ERROR,
    FILESTORE_REJECTION,
    HANDLER_ABANDON,
    HANDLER_IGNORE,
    HANDLER_SUSPEND,
    INACTIVITY_DETECTED,
    KEEP_ALIVE_LIMIT_REACHED,
    NAK_LIMIT_REACHED,
    NO_ERROR,
    POSITIVE_ACK_LIMIT_REACHED,
    STATUS_ACTIVE,
    STATUS_TERMINATED,
    STATUS_UNRECOGNIZED,
    UNACKNOWLEDGED,
    UNSUPPORTED_CHECKSUM_TYPE,
)
from obsw.cfdp.pdu.eof import EofPdu
from obsw.cfdp.pdu.filedata import FileDataPdu
from obsw.cfdp.pdu.header import PduHeader
from obsw.cfdp.pdu.metadata import MetadataPdu
from obsw.cfdp.tlv import FaultHandlerOverride
from obsw.crc import CHECKSUM_CRC32, checksum

DATA = payload(2000)


def pair(mode=ACKNOWLEDGED, **kw):
    return make_pair(files_a={"src.bin": DATA}, mode=mode, **kw)


def conditions(link, side):
    return [i.info["condition"] for i in link.finished(side)]


def is_file_data(pdu):
    return bool(pdu[0] & 0x10)


class TestTimersAndLimits(unittest.TestCase):
    def test_positive_ack_limit_at_sender(self):
        a, b = pair()
        a.put(2, "src.bin", "dst.bin")
        link = Link(a, b, drop=lambda side, pdu: side == 1)
        link.run()
        faults = [i.info["condition"] for i in link.kinds(0, "fault")]
        self.assertIn(POSITIVE_ACK_LIMIT_REACHED, faults)
        self.assertEqual(len(link.kinds(0, "abandoned")), 1)  # the EOF (cancel) got no ACK
        # the receiver had everything; its Finished never gets through, so it gives up too
        self.assertEqual(conditions(link, 1), [NO_ERROR])
        self.assertEqual(
            link.kinds(1, "abandoned")[0].info["condition"], POSITIVE_ACK_LIMIT_REACHED
        )
        self.assertEqual(a.tx, {})
        self.assertEqual(b.tx, {})

    def test_nak_limit_at_receiver(self):
        a, b = pair()
        a.put(2, "src.bin", "dst.bin")

        def drop(side, pdu):  # the segment at offset 640 never gets through
            return side == 0 and is_file_data(pdu) and pdu[-68:-64] == b"\x00\x00\x02\x80"

        link = Link(a, b, drop=drop)
        link.run()
        self.assertEqual(conditions(link, 1), [NAK_LIMIT_REACHED])
        self.assertEqual(conditions(link, 0), [NAK_LIMIT_REACHED])
        fin = link.finished(1)[0].info
        self.assertEqual((fin["delivery"], fin["file_status"]), (DATA_INCOMPLETE, FILE_DISCARDED))
        self.assertFalse("dst.bin" in b.fs.files)

    def test_inactivity_at_receiver(self):
        a, b = pair()
        a.put(2, "src.bin", "dst.bin")
        n = [0]

        def drop(side, pdu):
            n[0] += side == 0
            return side == 0 and n[0] > 3

        link = Link(a, b, drop=drop)
        link.run(max_time=200)
        self.assertEqual(conditions(link, 1)[0], INACTIVITY_DETECTED)

    def test_inactivity_at_class1_sender_waiting_for_finished(self):
        a, b = pair(mode=UNACKNOWLEDGED)
        a.put(2, "src.bin", "dst.bin", closure=True)
        link = Link(a, b, drop=lambda side, pdu: side == 1)
        link.run()
        self.assertEqual(conditions(link, 0), [INACTIVITY_DETECTED])
        self.assertEqual(conditions(link, 1), [NO_ERROR])

    def test_keep_alive_limit(self):
        a, b = pair(keep_alive_interval=0.5, keep_alive_limit=100)
        a.put(2, "src.bin", "dst.bin")
        first = [True]

        def drop(side, pdu):
            if side == 0 and is_file_data(pdu) and first[0]:
                first[0] = False
                return True
            return side == 1 and directive(pdu) == 8  # the NAKs are lost: progress stalls

        link = Link(a, b, drop=drop)
        link.run()
        faults = [i.info["condition"] for i in link.kinds(0, "fault")]
        self.assertIn(KEEP_ALIVE_LIMIT_REACHED, faults)
        self.assertEqual(conditions(link, 0)[0], KEEP_ALIVE_LIMIT_REACHED)

    def test_file_checksum_failure_class2(self):
        a, b = pair()
        a.put(2, "src.bin", "dst.bin")
        link = Link(a, b)
        orig = b.receive
        hit = [False]

        def receive(pdu, now):
            if not hit[0] and is_file_data(pdu):
                hit[0] = True
                pdu = pdu[:-1] + bytes((pdu[-1] ^ 1,))
            return orig(pdu, now)

        b.receive = receive
        link.run()
        self.assertEqual(conditions(link, 1), [FILE_CHECKSUM_FAILURE])
        self.assertEqual(conditions(link, 0), [FILE_CHECKSUM_FAILURE])

    def test_checksum_failure_ignored_by_override(self):
        a, b = pair()
        a.put(
            2,
            "src.bin",
            "dst.bin",
            fault_overrides=[FaultHandlerOverride(FILE_CHECKSUM_FAILURE, HANDLER_IGNORE)],
        )
        link = Link(a, b)
        orig = b.receive
        hit = [False]

        def receive(pdu, now):
            if not hit[0] and is_file_data(pdu):
                hit[0] = True
                pdu = pdu[:-1] + bytes((pdu[-1] ^ 1,))
            return orig(pdu, now)

        b.receive = receive
        link.run()
        self.assertEqual(conditions(link, 1), [NO_ERROR])
        self.assertEqual(link.kinds(1, "fault")[0].info["condition"], FILE_CHECKSUM_FAILURE)


class Crafted(unittest.TestCase):
    """PDUs built by hand to reach receiver faults a well-behaved sender never causes."""

    def header(self, mode=ACKNOWLEDGED, **kw):
        return PduHeader(1, 2, 99, mode=mode, seq_len=2, **kw)

    def test_file_size_error(self):
        a, b = pair()
        h = self.header()
        b.receive(MetadataPdu(h, 10, "s", "d", CHECKSUM_CRC32).pack(), 0)
        b.receive(FileDataPdu(h.copy(pdu_type=FILE_DATA), 0, b"x" * 20).pack(), 0)
        b.receive(EofPdu(h, 0, checksum(CHECKSUM_CRC32, b"x" * 10), 10).pack(), 0)
        fins = [i for i in b.pop_indications() if i.kind == "finished"]
        self.assertEqual(fins[0].info["condition"], FILE_SIZE_ERROR)

    def test_unsupported_checksum_is_ignored_by_default(self):
        a, b = pair()
        h = self.header()
        b.receive(MetadataPdu(h, 3, "s", "d", 7).pack(), 0)
        b.receive(FileDataPdu(h.copy(pdu_type=FILE_DATA), 0, b"abc").pack(), 0)
        b.receive(EofPdu(h, 0, 0x12345678, 3).pack(), 0)
        ind = b.pop_indications()
        self.assertEqual(
            [i.info["condition"] for i in ind if i.kind == "fault"], [UNSUPPORTED_CHECKSUM_TYPE]
        )
        fin = [i for i in ind if i.kind == "finished"][0].info
        self.assertEqual((fin["condition"], fin["file_status"]), (NO_ERROR, FILE_RETAINED))
        self.assertEqual(bytes(b.fs.files["d"]), b"abc")

    def test_filestore_rejection(self):
        a, b = pair()
        h = self.header()
        b.receive(MetadataPdu(h, 3, "s", "no/such/dir/d", CHECKSUM_CRC32).pack(), 0)
        b.receive(FileDataPdu(h.copy(pdu_type=FILE_DATA), 0, b"abc").pack(), 0)
        b.receive(EofPdu(h, 0, checksum(CHECKSUM_CRC32, b"abc"), 3).pack(), 0)
        fins = [i for i in b.pop_indications() if i.kind == "finished"]
        self.assertEqual(fins[0].info["condition"], FILESTORE_REJECTION)

    def test_late_eof_of_finished_transaction_is_acked(self):
        a, b = pair()
        h = self.header()
        b.receive(MetadataPdu(h, 0, None, None).pack(), 0)
        eof = EofPdu(h, 0, 0, 0).pack()
        b.receive(eof, 0)
        b.transmit(0)
        from obsw.cfdp.defs import DIR_FINISHED, TOWARD_RECEIVER
        from obsw.cfdp.pdu.ack import AckPdu

        ack = AckPdu(h.copy(direction=TOWARD_RECEIVER), DIR_FINISHED, 0)
        b.receive(ack.pack(), 0)
        self.assertEqual(b.tx, {})
        b.receive(eof, 1)
        out = b.transmit(1)
        self.assertEqual(len(out), 1)
        self.assertEqual(out[0][1][-1] & 3, STATUS_TERMINATED)


class TestUserRequests(unittest.TestCase):
    def test_cancel_at_sender_class2(self):
        a, b = pair()
        tid = a.put(2, "src.bin", "dst.bin")
        link = Link(a, b)
        link.step()
        self.assertTrue(a.cancel(tid, link.now))
        link.run()
        self.assertEqual(conditions(link, 0), [CANCEL_REQUEST_RECEIVED])
        self.assertEqual(conditions(link, 1), [CANCEL_REQUEST_RECEIVED])
        fin = link.finished(1)[0].info
        self.assertEqual(fin["file_status"], FILE_DISCARDED)
        self.assertFalse("dst.bin" in b.fs.files)
        self.assertEqual(a.tx, {})
        self.assertEqual(b.tx, {})

    def test_cancel_at_receiver_class2(self):
        a, b = pair()
        tid = a.put(2, "src.bin", "dst.bin")
        link = Link(a, b)
        link.step()
        self.assertTrue(b.cancel(tid, link.now))
        link.run()
        self.assertEqual(conditions(link, 1), [CANCEL_REQUEST_RECEIVED])
        self.assertEqual(conditions(link, 0), [CANCEL_REQUEST_RECEIVED])
        self.assertEqual(a.tx, {})

    def test_cancel_class1(self):
        a, b = pair(mode=UNACKNOWLEDGED)
        tid = a.put(2, "src.bin", "dst.bin", closure=False)
        link = Link(a, b)
        link.step()
        a.cancel(tid, link.now)
        link.run()
        self.assertEqual(conditions(link, 0), [CANCEL_REQUEST_RECEIVED])
        self.assertEqual(conditions(link, 1), [CANCEL_REQUEST_RECEIVED])

    def test_cancel_unknown(self):
        a, b = pair()
        self.assertFalse(a.cancel((1, 999), 0))

    def test_suspend_and_resume_sender(self):
        a, b = pair()
        tid = a.put(2, "src.bin", "dst.bin")
        link = Link(a, b)
        link.step()
        self.assertTrue(a.suspend(tid, link.now))
        self.assertFalse(a.suspend(tid, link.now))
        before = link.sent[0]
        for _ in range(5):
            link.step()
        self.assertEqual(link.sent[0], before)
        self.assertEqual(link.kinds(0, "suspended")[0].info["condition"], 14)
        link.now += 5
        self.assertTrue(a.resume(tid, link.now))
        link.run()
        self.assertEqual(len(link.kinds(0, "resumed")), 1)
        self.assertEqual(bytes(b.fs.files["dst.bin"]), DATA)
        self.assertEqual(conditions(link, 0), [NO_ERROR])

    def test_suspend_receiver_freezes_its_timers(self):
        a, b = pair()
        tid = a.put(2, "src.bin", "dst.bin")
        link = Link(
            a,
            b,
            drop=lambda side, pdu: (
                side == 0 and link.now < 100 and is_file_data(pdu) and pdu[-1] & 1
            ),
        )
        link.run(until=lambda: b.find(tid) is not None)
        link.run(until=lambda: b.find(tid) is not None and b.find(tid).eof is not None)
        b.suspend(tid, link.now)
        self.assertIsNone(b.find(tid).deadline())
        link.now = 150.0
        b.resume(tid, link.now)
        link.run()
        self.assertEqual(bytes(b.fs.files["dst.bin"]), DATA)
        self.assertEqual(conditions(link, 1), [NO_ERROR])

    def test_suspend_by_fault_handler_override(self):
        a, b = pair(ack_interval=400.0)
        tid = a.put(
            2,
            "src.bin",
            "dst.bin",
            fault_overrides=[FaultHandlerOverride(INACTIVITY_DETECTED, HANDLER_SUSPEND)],
        )
        n = [0]

        def drop(side, pdu):
            n[0] += side == 0
            return side == 0 and n[0] > 3 and link.now < 1000

        link = Link(a, b, drop=drop)
        link.run(max_time=100)
        sus = link.kinds(1, "suspended")
        self.assertEqual(sus[0].info["condition"], INACTIVITY_DETECTED)
        self.assertTrue(b.find(tid).suspended)
        link.now = 1000.0
        b.resume(tid, link.now)
        link.run()
        self.assertEqual(bytes(b.fs.files["dst.bin"]), DATA)

    def test_abandon_by_fault_handler_override(self):
        a, b = pair()
        a.put(
            2,
            "src.bin",
            "dst.bin",
            fault_overrides=[FaultHandlerOverride(POSITIVE_ACK_LIMIT_REACHED, HANDLER_ABANDON)],
        )
        link = Link(a, b, drop=lambda side, pdu: side == 1)
        link.run(max_time=100)
        self.assertEqual(
            link.kinds(0, "abandoned")[0].info["condition"], POSITIVE_ACK_LIMIT_REACHED
        )
        self.assertEqual(a.tx, {})

    def test_report(self):
        a, b = pair()
        tid = a.put(2, "src.bin", "dst.bin")
        rep = a.report(tid)
        self.assertEqual((rep["status"], rep["role"], rep["progress"]), (STATUS_ACTIVE, "S", 0))
        link = Link(a, b)
        link.run()
        self.assertEqual(a.report(tid)["status"], STATUS_TERMINATED)
        self.assertEqual(a.report((1, 77))["status"], STATUS_UNRECOGNIZED)
        self.assertEqual(len(link.kinds(0, "report")) + len(a.pop_indications()), 3)


if __name__ == "__main__":
    unittest.main()
