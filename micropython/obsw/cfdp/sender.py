"""The sending side of a CFDP transaction (727.0-B-5 4.6.1, 4.6.4 to 4.6.6), classes 1 and 2."""

import struct
from binascii import hexlify, unhexlify

from obsw.cfdp.defs import (
    ACKNOWLEDGED,
    DATA_COMPLETE,
    DIR_ACK,
    DIR_EOF,
    DIR_FINISHED,
    DIR_KEEP_ALIVE,
    DIR_NAK,
    FILE_DATA,
    FILE_DIRECTIVE,
    FILE_STATUS_UNREPORTED,
    INACTIVITY_DETECTED,
    KEEP_ALIVE_LIMIT_REACHED,
    NO_ERROR,
    POSITIVE_ACK_LIMIT_REACHED,
    STATUS_ACTIVE,
)
from obsw.cfdp.pdu.ack import AckPdu
from obsw.cfdp.pdu.eof import EofPdu
from obsw.cfdp.pdu.header import PduHeader
from obsw.cfdp.pdu.metadata import MetadataPdu
from obsw.cfdp.pdu.prompt import PromptPdu
from obsw.cfdp.timers import Timer
from obsw.cfdp.tlv import pack_tlvs, unpack_tlvs
from obsw.cfdp.transaction import Transaction
from obsw.compat import CFDP_READ_AHEAD
from obsw.crc import FileChecksum, crc16_ccitt

# sender states
SENDING = "sending"
WAIT_EOF_ACK = "wait_eof_ack"
WAIT_FINISHED = "wait_finished"


def add_interval(lst, s, e):
    """Union [s, e) into a sorted list of disjoint [start, end) lists."""
    i = 0
    n = len(lst)
    while i < n and lst[i][1] < s:
        i += 1
    j = i
    while j < n and lst[j][0] <= e:
        s = min(s, lst[j][0])
        e = max(e, lst[j][1])
        j += 1
    lst[i:j] = [[s, e]]


class Sender(Transaction):
    """Copies one file (or only metadata) to a remote entity."""

    role = "S"

    def __init__(self, entity, tid, remote, req, now):
        super().__init__(entity, tid, remote, req["mode"])
        self.req = req
        fs = entity.fs
        self.source_name = req.get("source_name")
        self.dest_name = req.get("dest_name")
        self.size = fs.size(self.source_name) if self.source_name else 0
        self.options = list(req.get("options", ()))
        self.set_overrides(self.options)
        self.closure = req["closure"]
        self.checksum_type = req["checksum"]
        large = req.get("large") or remote.large or self.size >> 32 != 0
        self.header = PduHeader(
            tid[0],
            remote.entity_id,
            tid[1],
            mode=self.mode,
            crc=remote.crc,
            large=large,
            seg_ctrl=req.get("seg_ctrl", False),
            eid_len=remote.eid_len or 0,
            seq_len=entity.mib.seq_len,
        )
        if remote.eid_len == 0:
            self.header.eid_len = max(self.header.eid_len, 1)
        self.segment = remote.max_segment
        self.state_ = SENDING
        self.meta_pending = True
        self.progress = 0
        self.resend = []
        self.cancelling = False
        self.eof = None
        self.peer_progress = 0
        self.ck = FileChecksum(self.checksum_type)
        self._fh = None
        self.ack = Timer(remote.ack_interval, remote.ack_limit)
        self.inactivity = Timer(remote.inactivity)
        self.timers = (self.ack, self.inactivity)
        self._prepare_fast_path()
        self._ra = None  # (offset, bytes): the last read-ahead chunk of the file

    def _prepare_fast_path(self):
        h = self.header.copy(pdu_type=FILE_DATA)
        raw = h.pack(0)
        self._fd_b0 = raw[:1]
        self._fd_rest = raw[3:]
        self._fd_fmt = ">Q" if h.large else ">I"
        self._fd_fss = 8 if h.large else 4
        self._crc = h.crc

    def _file(self):
        if self._fh is None:
            self._fh = self.entity.fs.open_read(self.source_name)
        return self._fh

    def release(self):
        self._ra = None
        if self._fh is not None:
            self._fh.close()
            self._fh = None

    def progress_of(self):
        return self.progress

    def directive_header(self):
        return self.header.copy(pdu_type=FILE_DIRECTIVE)

    # -- building PDUs ---------------------------------------------------------------------
    def _read(self, offset, n):
        """``n`` octets of the file at ``offset``: cut from the last read-ahead chunk when it
        holds them, else read (with CFDP_READ_AHEAD, a chunk that large from ``offset``, which
        the running file checksum takes in whole when it continues it: EOF's checksum is over
        the whole file, and one of a transfer cut short is computed again from the file)."""
        ra = self._ra
        if ra is not None:
            start = ra[0]
            if start <= offset and offset + n <= start + len(ra[1]):
                return ra[1][offset - start : offset - start + n]
        if CFDP_READ_AHEAD <= n:
            return self._file().read(offset, n)
        chunk = self._file().read(offset, CFDP_READ_AHEAD)
        self._ra = (offset, chunk)
        if self.ck.offset == offset:  # the file checksum over the chunk at once, not per PDU
            self.ck.update(chunk)
        return chunk[:n]

    def _file_data(self, offset, n):
        data = self._read(offset, n)
        dl = self._fd_fss + len(data) + (2 if self._crc else 0)
        pdu = b"".join(
            (
                self._fd_b0,
                struct.pack(">H", dl),
                self._fd_rest,
                struct.pack(self._fd_fmt, offset),
                data,
            )
        )
        if self._crc:
            pdu += struct.pack(">H", crc16_ccitt(pdu))
        return pdu, data

    def metadata_pdu(self):
        return MetadataPdu(
            self.directive_header(),
            self.size,
            self.source_name,
            self.dest_name,
            self.checksum_type,
            self.closure,
            self.options,
        ).pack()

    def _checksum_upto(self, n):
        if self.ck.offset != n:
            ck = FileChecksum(self.checksum_type)
            pos = 0
            while pos < n:
                k = min(65536, n - pos)
                ck.update(self._file().read(pos, k))
                pos += k
            self.ck = ck
        return self.ck.value

    def _send_eof(self, condition, now, fault_location=None):
        size = self.size if condition == NO_ERROR else self.progress
        checksum = 0
        if self.source_name:
            try:
                checksum = self._checksum_upto(size)
            except OSError:
                if condition == NO_ERROR:
                    raise
                # the file went away (the fault being reported): the EOF (cancel) still goes
                # out so the receiver is told; it does not check a cancelled file's checksum
        hdr = self.directive_header()
        self.eof = EofPdu(hdr, condition, checksum, size, fault_location).pack()
        self.indicate("eof_sent")
        if self.mode == ACKNOWLEDGED:
            self.state_ = WAIT_EOF_ACK
            self.ack.start(now, reset_count=True)
            self.save(force=True)
        elif condition != NO_ERROR:
            self.complete(condition, 1, FILE_STATUS_UNREPORTED, (), now)
        elif self.closure:
            self.state_ = WAIT_FINISHED
            self.inactivity.start(now, reset_count=True)
        else:
            self.complete(NO_ERROR, DATA_COMPLETE, FILE_STATUS_UNREPORTED, (), now)
        return self.eof

    def next_pdu(self, now):
        """The next PDU this transaction wants to send, or None (nothing now)."""
        if self.done or self.suspended:
            return None
        if self.meta_pending:
            self.meta_pending = False
            return self.metadata_pdu()
        if self.resend:
            seg = self.resend[0]
            s = seg[0]
            n = min(self.segment, seg[1] - s)
            seg[0] = s + n
            if seg[0] >= seg[1]:
                self.resend.pop(0)
            pdu, data = self._file_data(s, n)
            st = self.entity.stats
            st["retransmitted_pdus"] += 1
            st["retransmitted_bytes"] += len(data)
            return pdu
        if self.state_ != SENDING or self.cancelling:
            return None
        if self.progress < self.size:
            off = self.progress
            pdu, data = self._file_data(off, min(self.segment, self.size - off))
            if self.ck.offset == off:
                self.ck.update(data)
            self.progress = off + len(data)
            self.entity.stats["file_bytes_sent"] += len(data)
            if self.progress - self._saved_at >= self.entity.checkpoint_bytes:
                self._saved_at = self.progress
                self.save()
            return pdu
        return self._send_eof(NO_ERROR, now)

    def has_data(self):
        if self.done or self.suspended:
            return False
        return (
            self.meta_pending
            or bool(self.resend)
            or (self.state_ == SENDING and not self.cancelling)
        )

    # -- incoming PDUs ---------------------------------------------------------------------
    def on_pdu(self, pdu, now):
        if self.done:
            return
        if self.inactivity.running:
            self.inactivity.start(now)
        code = pdu.CODE
        if code == DIR_ACK:
            if pdu.directive == DIR_EOF and self.state_ == WAIT_EOF_ACK:
                self.ack.stop()
                if self.cancelling:
                    self.complete(self.condition, 1, FILE_STATUS_UNREPORTED, (), now)
                else:
                    self.state_ = WAIT_FINISHED
                    self.inactivity.start(now, reset_count=True)
                    self.save(force=True)
            return
        if code == DIR_FINISHED:
            if self.mode == ACKNOWLEDGED:
                ack = AckPdu(self.directive_header(), DIR_FINISHED, pdu.condition, STATUS_ACTIVE)
                self.emit(ack.pack())
            if self.state_ == SENDING and not self.cancelling and pdu.condition == NO_ERROR:
                # a Finished before our EOF went out cannot be a verdict on this file
                return
            self.complete(pdu.condition, pdu.delivery, pdu.file_status, pdu.responses, now)
        elif code == DIR_NAK:
            if self.cancelling or self.mode != ACKNOWLEDGED:
                return
            self.entity.stats["naks_received"] += 1
            limit = self.progress if self.state_ == SENDING else self.size
            for s, e in pdu.segments:
                if s == 0 and e == 0:
                    self.meta_pending = True
                    continue
                e = min(e, limit)
                if s < e:
                    add_interval(self.resend, s, e)
        elif code == DIR_KEEP_ALIVE:
            self.peer_progress = pdu.progress
            lim = self.remote.keep_alive_limit
            if lim is not None and self.progress - pdu.progress > lim:
                self.fault(KEEP_ALIVE_LIMIT_REACHED, now)

    # -- requests and timers ---------------------------------------------------------------
    def prompt(self, kind, now):
        if self.done or self.mode != ACKNOWLEDGED:
            return False
        self.emit(PromptPdu(self.directive_header(), kind).pack())
        return True

    def cancel(self, condition, now, fault_location):
        if self.done:
            return
        if self.cancelling:
            # a fault while the EOF (cancel) is in flight ends the transaction at once
            self.abandon(condition)
            return
        self.cancelling = True
        self.condition = condition
        self.resend = []
        self.meta_pending = False
        self.emit(self._send_eof(condition, now, fault_location))

    def poll(self, now):
        if self.done or self.suspended:
            return
        if self.ack.expired(now):
            if self.ack.expire(now):
                if self.cancelling:
                    self.abandon(POSITIVE_ACK_LIMIT_REACHED)
                else:
                    self.fault(POSITIVE_ACK_LIMIT_REACHED, now)
                return
            self.entity.stats["eof_resent"] += 1
            self.emit(self.eof)
        if self.inactivity.expired(now):
            self.inactivity.start(now)
            self.fault(INACTIVITY_DETECTED, now)

    def complete(self, condition, delivery, file_status, responses, now):
        self.condition = condition
        self.indicate(
            "finished",
            role="S",
            condition=condition,
            delivery=delivery,
            file_status=file_status,
            responses=list(responses),
            progress=self.progress,
            size=self.size,
        )
        self.close()
        self.entity.sender_finished(self, condition, delivery, file_status, responses, now)

    # -- persistence -----------------------------------------------------------------------
    def state(self):
        req = self.req
        return {
            "dest_id": self.remote.entity_id,
            "source_name": self.source_name,
            "dest_name": self.dest_name,
            "closure": self.closure,
            "checksum": self.checksum_type,
            "seg_ctrl": req.get("seg_ctrl", False),
            "large": self.header.large,
            "options": hexlify(pack_tlvs(self.options)).decode(),
            "progress": self.progress,
            "resend": self.resend,
            "state": self.state_,
            "cancelling": self.cancelling,
            "eof": hexlify(self.eof).decode() if self.eof else None,
        }

    @classmethod
    def restored(cls, entity, st, remote, now):
        req = {
            "mode": st["mode"],
            "source_name": st["source_name"],
            "dest_name": st["dest_name"],
            "closure": st["closure"],
            "checksum": st["checksum"],
            "seg_ctrl": st["seg_ctrl"],
            "large": st["large"],
            "options": unpack_tlvs(unhexlify(st["options"])),
        }
        tx = cls(entity, tuple(st["tid"]), remote, req, now)
        tx.restore_common(st, now)
        tx.progress = min(st["progress"], tx.size)
        tx.resend = st["resend"]
        tx.state_ = st["state"]
        tx.cancelling = st["cancelling"]
        tx.eof = unhexlify(st["eof"]) if st["eof"] else None
        tx._saved_at = tx.progress
        if tx.state_ == WAIT_EOF_ACK and tx.eof and not tx.suspended:
            tx.emit(tx.eof)
            tx.ack.start(now)
        return tx
