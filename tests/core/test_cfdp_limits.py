"""CFDP receiving limits: what a sender says about offsets, sizes and transactions never
decides this entity's memory; violations are faults with their condition codes."""

import unittest

from cfdp_sim import make_pair
from obsw.cfdp.defs import (
    ACKNOWLEDGED,
    DIR_NAK,
    FILE_DATA,
    FILE_SIZE_ERROR,
    FILESTORE_REJECTION,
    HANDLER_IGNORE,
    UNACKNOWLEDGED,
)
from obsw.cfdp.pdu import decode_pdu
from obsw.cfdp.pdu.eof import EofPdu
from obsw.cfdp.pdu.filedata import FileDataPdu
from obsw.cfdp.pdu.header import PduHeader
from obsw.cfdp.pdu.metadata import MetadataPdu
from obsw.cfdp.tlv import FaultHandlerOverride
from obsw.crc import CHECKSUM_CRC32

LIMIT = 4096


def receiver(**kw):
    kw.setdefault("max_file_size", LIMIT)
    return make_pair(**kw)[1]


def header(seq=99, mode=ACKNOWLEDGED, **kw):
    return PduHeader(1, 2, seq, mode=mode, seq_len=2, **kw)


def data_pdu(h, offset, data):
    return FileDataPdu(h.copy(pdu_type=FILE_DATA), offset, data).pack()


def faults(ent):
    return [i.info["condition"] for i in ent.pop_indications() if i.kind == "fault"]


def part_sizes(ent):
    return [len(v) for k, v in ent.fs.files.items() if k.endswith(".part")]


class TestLimits(unittest.TestCase):
    def test_file_data_far_beyond_the_limit_is_refused_not_allocated(self):
        b = receiver()
        h = header()
        for offset in (LIMIT, 1 << 31, 0xFFFFFFFF):
            b.receive(data_pdu(h, offset, b"x" * 8), 0)
        self.assertEqual(b.stats["oversize"], 1)  # the first cancels the transaction
        self.assertEqual(max(part_sizes(b) + [0]), 0)
        self.assertEqual(b.stats["internal_errors"], 0)

    def test_ignore_handler_does_not_lift_the_limit(self):
        b = receiver()
        h = header()
        ignore = FaultHandlerOverride(FILESTORE_REJECTION, HANDLER_IGNORE)
        b.receive(MetadataPdu(h, 0, "s", "d", CHECKSUM_CRC32, options=[ignore]).pack(), 0)
        b.receive(data_pdu(h, 1 << 30, b"x" * 8), 0)
        b.receive(data_pdu(h, 0, b"abc"), 0)
        self.assertEqual(faults(b)[:1], [FILESTORE_REJECTION])
        self.assertEqual(part_sizes(b), [3])

    def test_large_file_offsets_beyond_the_limit(self):
        b = receiver()
        h = header(large=True)
        b.receive(data_pdu(h, (1 << 40) - 3, b"xyz"), 0)
        self.assertEqual(faults(b), [FILESTORE_REJECTION])
        self.assertEqual(b.stats["oversize"], 1)

    def test_declared_sizes_beyond_the_limit(self):
        b = receiver()
        b.receive(MetadataPdu(header(1), LIMIT + 1, "s", "d", CHECKSUM_CRC32).pack(), 0)
        b.receive(EofPdu(header(2), 0, 0, 1 << 31).pack(), 0)
        self.assertEqual(b.stats["oversize"], 2)
        self.assertEqual(b.stats["internal_errors"], 0)

    def test_data_beyond_the_metadata_size_is_a_file_size_error(self):
        b = receiver()
        h = header()
        b.receive(MetadataPdu(h, 10, "s", "d", CHECKSUM_CRC32).pack(), 0)
        b.receive(data_pdu(h, 8, b"abcd"), 0)
        self.assertEqual(faults(b), [FILE_SIZE_ERROR])

    def test_naks_always_encodable(self):
        b = receiver(max_file_size=1 << 40)  # more than a small-file NAK can express
        h = header()
        b.receive(data_pdu(h, 0xFFFFFFFC, b"x" * 8), 0)  # ends beyond 32 bits: refused
        self.assertEqual(faults(b), [FILESTORE_REJECTION])
        h = header(100)
        b.receive(MetadataPdu(h, 0, "s", "d", CHECKSUM_CRC32).pack(), 0)
        b.receive(EofPdu(h, 0, 0, 0xFFFFFF00).pack(), 0)  # a gap up to 32 bits: NAKed
        sent = [decode_pdu(raw) for _dest, raw in b.transmit(0, 64)]
        self.assertTrue([p for p in sent if p.CODE == DIR_NAK])
        self.assertEqual(b.stats["internal_errors"], 0)

    def test_gaps_are_bounded(self):
        b = receiver(max_gaps=8, mode=UNACKNOWLEDGED)
        h = header(mode=UNACKNOWLEDGED)
        for k in range(100):
            b.receive(data_pdu(h, 2 * k, b"x"), 0)
        tx = b.tx[((1, 99), "R")]
        self.assertEqual(len(tx.gaps), 8)
        b.receive(EofPdu(h, 0, 0, 200).pack(), 0)
        self.assertEqual(b.stats["internal_errors"], 0)

    def test_the_gap_bound_merges_the_closest_gaps(self):
        """Over the bound, the two gaps with the fewest received octets between them merge
        (merging the last two would ask again for everything received after the bound)."""
        h = header(mode=UNACKNOWLEDGED)
        chunks = ((10, 10), (30, 100), (140, 1), (150, 100))  # gaps [0,10) [20,30) .. [141,150)
        b = receiver(max_gaps=4, mode=UNACKNOWLEDGED)
        for offset, n in chunks:
            b.receive(data_pdu(h, offset, b"x" * n), 0)
        tx = b.tx[((1, 99), "R")]
        self.assertEqual([g[:2] for g in tx.gaps], [[0, 10], [20, 30], [130, 140], [141, 150]])
        b.receive(data_pdu(h, 260, b"x"), 0)  # a fifth gap [250, 260): one above the bound
        self.assertEqual([g[:2] for g in tx.gaps], [[0, 10], [20, 30], [130, 150], [250, 260]])

    def test_concurrent_transactions_are_bounded(self):
        b = receiver()
        b.mib.max_transactions = 5
        for seq in range(1, 20):
            b.receive(data_pdu(header(seq), 0, b"x"), 0)
        self.assertEqual(len(b.tx), 5)
        self.assertEqual(b.stats["refused"], 14)


if __name__ == "__main__":
    unittest.main()
