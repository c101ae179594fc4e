"""The receiving side of a CFDP transaction (727.0-B-5 4.6.1.2, 4.6.3, 4.6.4), classes 1 and 2:
gap tracking, immediate and deferred NAKs, check, NAK, ACK, keep-alive and inactivity timers."""

from obsw.cfdp.defs import (
    ACKNOWLEDGED,
    CHECK_LIMIT_REACHED,
    DATA_COMPLETE,
    DATA_INCOMPLETE,
    DIR_ACK,
    DIR_EOF,
    DIR_FINISHED,
    DIR_METADATA,
    DIR_PROMPT,
    FILE_CHECKSUM_FAILURE,
    FILE_DIRECTIVE,
    FILE_DISCARDED,
    FILE_DISCARDED_FILESTORE,
    FILE_RETAINED,
    FILE_SIZE_ERROR,
    FILE_STATUS_UNREPORTED,
    FILESTORE_REJECTION,
    INACTIVITY_DETECTED,
    NAK_LIMIT_REACHED,
    NO_ERROR,
    POSITIVE_ACK_LIMIT_REACHED,
    PROMPT_KEEP_ALIVE,
    STATUS_ACTIVE,
    TLV_FILESTORE_REQUEST,
    TLV_MESSAGE_TO_USER,
    TOWARD_SENDER,
    UNSUPPORTED_CHECKSUM_TYPE,
)
from obsw.cfdp.filestore import execute_requests
from obsw.cfdp.pdu.ack import AckPdu
from obsw.cfdp.pdu.finished import FinishedPdu
from obsw.cfdp.pdu.keepalive import KeepAlivePdu
from obsw.cfdp.pdu.nak import NakPdu
from obsw.cfdp.timers import Timer
from obsw.cfdp.transaction import Transaction
from obsw.crc import CHECKSUM_NULL, FileChecksum, UnsupportedChecksumError

RECEIVING = "receiving"
WAIT_FIN_ACK = "wait_finished_ack"


def _merge_closest(gaps):
    """Merge the two neighbouring gaps with the fewest received octets between them."""
    best = 0
    least = None
    for i in range(len(gaps) - 1):
        between = gaps[i + 1][0] - gaps[i][1]
        if least is None or between < least:
            least = between
            best = i
    g = gaps[best]
    g[1] = gaps.pop(best + 1)[1]


class Receiver(Transaction):
    """Receives one file (or only metadata) from a remote entity."""

    role = "R"

    def __init__(self, entity, tid, remote, header, now):
        super().__init__(entity, tid, remote, header.mode)
        self.header = header.copy(direction=TOWARD_SENDER, pdu_type=FILE_DIRECTIVE)
        self.meta = None  # dict once the Metadata PDU arrived
        self.part = entity.work_name("rx-%d-%d.part" % tid)
        self._fh = None
        self.progress = 0  # end of the highest segment received
        self.gaps = []  # [start, end, time NAKed or None], sorted, disjoint
        self.eof = None  # (checksum, size) of an EOF (no error)
        self.state_ = RECEIVING
        self.received = 0
        self.ck = None
        self.finished = None
        self.ack = Timer(remote.ack_interval, remote.ack_limit)
        self.nak = Timer(remote.nak_interval, remote.nak_limit)
        self.inactivity = Timer(remote.inactivity)
        self.keep_alive = Timer(remote.keep_alive_interval)
        self.check = Timer(remote.check_interval, remote.check_limit)
        self.timers = (self.ack, self.nak, self.inactivity, self.keep_alive, self.check)
        self.inactivity.start(now)
        if self.mode == ACKNOWLEDGED:
            self.keep_alive.start(now)

    def release(self):
        if self._fh is not None:
            self._fh.close()
            self._fh = None

    def progress_of(self):
        return self.gaps[0][0] if self.gaps else self.progress

    # -- gaps ------------------------------------------------------------------------------
    def _fill(self, s, e):
        """Remove [s, e) from the gaps; True if anything missing arrived."""
        gaps = self.gaps
        lo = 0
        hi = len(gaps)
        while lo < hi:  # first gap ending after s
            mid = (lo + hi) // 2
            if gaps[mid][1] <= s:
                lo = mid + 1
            else:
                hi = mid
        i = lo
        got = False
        while i < len(gaps) and gaps[i][0] < e:
            g = gaps[i]
            got = True
            if g[0] < s and g[1] > e:
                gaps.insert(i + 1, [e, g[1], g[2]])
                g[1] = s
                return True
            if g[0] < s:
                g[1] = s
                i += 1
            elif g[1] > e:
                g[0] = e
                return True
            else:
                gaps.pop(i)
        return got

    def missing(self):
        return bool(self.gaps) or self.meta is None or self.eof is None

    # -- NAKs ------------------------------------------------------------------------------
    def _send_naks(self, segments, start, end):
        if not segments:
            return
        hdr = self.header
        per = NakPdu.max_segments(hdr, self.remote.max_pdu)
        i = 0
        while i < len(segments):
            chunk = segments[i : i + per]
            s = start if i == 0 else chunk[0][0]
            e = end if i + per >= len(segments) else chunk[-1][1]
            self.emit(NakPdu(hdr, s, e, chunk).pack())
            self.entity.stats["naks_sent"] += 1
            i += per

    def _nak_all(self, now, only_new=False, upto=None, settle=None):
        """NAK the gaps (``only_new``: never asked for; ``upto``: below an offset;
        ``settle``: not asked for within that many seconds, their data may be on its way)."""
        segs = []
        if self.meta is None:
            segs.append((0, 0))
        for g in self.gaps:
            if upto is not None and g[0] >= upto:
                break
            if only_new and g[2] is not None:
                continue
            if settle is not None and g[2] is not None and now - g[2] < settle:
                continue
            g[2] = now
            segs.append((g[0], g[1]))
        end = upto if upto is not None else (self.eof[1] if self.eof else self.progress)
        self._send_naks(segs, 0, end)

    # -- incoming PDUs ---------------------------------------------------------------------
    def on_pdu(self, pdu, now):
        if self.done:
            return
        if self.state_ == RECEIVING:
            self.inactivity.start(now)
        code = pdu.CODE
        if code is None:
            self.on_file_data(pdu.offset, pdu.data, now)
        elif code == DIR_METADATA:
            self.on_metadata(pdu, now)
        elif code == DIR_EOF:
            self.on_eof(pdu, now)
        elif code == DIR_ACK:
            if pdu.directive == DIR_FINISHED and self.state_ == WAIT_FIN_ACK:
                self.ack.stop()
                self.close()
        elif code == DIR_PROMPT:
            self.on_prompt(pdu.response, now)

    def limit(self):
        """The largest file this transaction may write: the remote's ``max_file_size``, and
        what the PDU header's file size field can express (a NAK must be able to ask)."""
        cap = self.remote.max_file_size
        if not self.header.large and cap > 0xFFFFFFFF:
            cap = 0xFFFFFFFF
        return cap

    def on_metadata(self, pdu, now):
        if self.meta is not None or self.state_ != RECEIVING:
            return
        if pdu.file_size > self.limit():
            self.entity.stats["oversize"] += 1
            self.fault(FILESTORE_REJECTION, now)
            if self.done or self.suspended:
                return
        dest = pdu.dest_name
        if dest and pdu.source_name and self.entity.fs.is_dir(dest):
            base = pdu.source_name.replace("\\", "/").split("/")[-1]
            dest = dest.rstrip("/") + "/" + base
        self.meta = {
            "source_name": pdu.source_name,
            "dest_name": dest,
            "size": pdu.file_size,
            "checksum": pdu.checksum_type,
            "closure": pdu.closure,
            "options": pdu.options,
        }
        self.set_overrides(pdu.options)
        self.messages = [t for t in pdu.options if t.tlv_type == TLV_MESSAGE_TO_USER]
        self.entity.note_messages(self)
        self.indicate(
            "metadata",
            source_name=pdu.source_name,
            dest_name=dest,
            size=pdu.file_size,
            messages=self.messages,
        )
        try:
            if pdu.checksum_type != CHECKSUM_NULL:
                # from offset 0: data that came before the metadata is read back at the end
                self.ck = FileChecksum(pdu.checksum_type)
        except UnsupportedChecksumError:
            self.ck = None
            if not self.fault(UNSUPPORTED_CHECKSUM_TYPE, now):
                return
        self.save(force=True)
        self._check_done(now)

    def sync_data(self):
        fh = self._fh
        if fh is not None:
            sync = getattr(fh, "sync", None)
            if sync is not None:
                sync()

    def _file(self):
        if self._fh is None:
            fs = self.entity.fs
            self._fh = fs.open_write(self.part, not fs.exists(self.part))
        return self._fh

    def on_file_data_pdu(self, offset, data, now):
        """A file data PDU from the entity's fast path: what ``on_pdu`` does with one."""
        if self.done:
            return
        if self.state_ == RECEIVING:
            self.inactivity.start(now)
        self.on_file_data(offset, data, now)

    def on_file_data(self, offset, data, now):
        if self.state_ != RECEIVING:
            return
        n = len(data)
        end = offset + n
        if end > self.limit():
            # never written, whatever the fault handler says: no sender decides our memory
            self.entity.stats["oversize"] += 1
            self.fault(FILESTORE_REJECTION, now)
            return
        size = self.eof[1] if self.eof is not None else self.meta["size"] if self.meta else 0
        if size and end > size:
            if not self.fault(FILE_SIZE_ERROR, now):
                return
        try:
            self._file().write(offset, data)
        except OSError:
            self.fault(FILESTORE_REJECTION, now)
            return
        self.received += n
        ck = self.ck
        if ck is not None and ck.offset == offset:
            ck.update(data)
        progress = self.progress
        if offset > progress:
            gaps = self.gaps
            gaps.append([progress, offset, None])
            if len(gaps) > self.remote.max_gaps:
                _merge_closest(gaps)  # bounded: the fewest octets are asked again
            if self.mode == ACKNOWLEDGED and self.remote.immediate_nak and not self.suspended:
                self.gaps[-1][2] = now
                self._send_naks([(progress, offset)], progress, end)
        if end > progress:
            self.progress = end
        if offset < progress and self.gaps:
            if self._fill(offset, min(end, progress)):
                self.nak.count = 0  # progress resets the NAK limit (4.6.4.7)
        if self.eof is not None:
            self._check_done(now)
        elif self.received - self._saved_at >= self.entity.checkpoint_bytes:
            self._saved_at = self.received
            self.save()

    def on_eof(self, pdu, now):
        if self.mode == ACKNOWLEDGED:
            self.emit(AckPdu(self.header, DIR_EOF, pdu.condition, STATUS_ACTIVE).pack())
        if self.state_ != RECEIVING or self.eof is not None:
            return
        if pdu.condition != NO_ERROR:
            # the sender cancelled: cancel response procedure (4.11.2.3)
            self.indicate("eof_recv", condition=pdu.condition)
            self.notice_of_completion(
                pdu.condition, DATA_INCOMPLETE, (), now, self.remote.entity_id
            )
            return
        size = pdu.file_size
        if size > self.limit():
            self.entity.stats["oversize"] += 1
            self.fault(FILESTORE_REJECTION, now)
            return
        self.eof = (pdu.checksum, size)
        self.indicate("eof_recv", condition=NO_ERROR, size=size)
        if self.progress > size:
            if not self.fault(FILE_SIZE_ERROR, now):
                return
        elif size > self.progress:
            self.gaps.append([self.progress, size, None])
            self.progress = size
        self.save(force=True)
        if self._check_done(now):
            return
        if self.mode == ACKNOWLEDGED:
            if not self.suspended:
                self._nak_all(now, only_new=self.remote.immediate_nak)
            self.nak.start(now, reset_count=True)
        else:
            self.check.start(now, reset_count=True)

    def on_prompt(self, response, now):
        if self.mode != ACKNOWLEDGED or self.state_ != RECEIVING:
            return
        if response == PROMPT_KEEP_ALIVE:
            self._keep_alive()
        else:
            self._nak_all(now, upto=self.progress)

    def _keep_alive(self):
        self.emit(KeepAlivePdu(self.header, self.progress_of()).pack())

    # -- completion ------------------------------------------------------------------------
    def _check_done(self, now):
        if self.state_ != RECEIVING or self.missing() or self.suspended:
            return False
        self.nak.stop()
        self.check.stop()
        self._complete(now)
        return True

    def _verify(self):
        ctype = self.meta["checksum"]
        if ctype == CHECKSUM_NULL or not self.meta["dest_name"]:
            return True
        ck = self.ck
        if ck is None:
            try:
                ck = FileChecksum(ctype)
            except UnsupportedChecksumError:
                return True  # the fault was declared at metadata and ignored
        size = self.eof[1]
        fh = self._file() if size else None
        while ck.offset < size:
            ck.update(fh.read(ck.offset, min(65536, size - ck.offset)))
        return ck.value == self.eof[0]

    def _complete(self, now):
        self.sync_data()  # the whole file on the medium before it is renamed and reported
        if not self._verify():
            if not self.fault(FILE_CHECKSUM_FAILURE, now):
                return
        status = FILE_STATUS_UNREPORTED
        dest = self.meta["dest_name"]
        fs = self.entity.fs
        if dest:
            self.release()
            try:
                if not fs.exists(self.part):
                    fs.write_bytes(self.part, b"")
                fs.rename(self.part, dest)
                status = FILE_RETAINED
            except OSError:
                if not self.fault(FILESTORE_REJECTION, now):
                    return
                status = FILE_DISCARDED_FILESTORE
        reqs = [t for t in self.meta["options"] if t.tlv_type == TLV_FILESTORE_REQUEST]
        responses = execute_requests(fs, reqs) if reqs else []
        self.notice_of_completion(NO_ERROR, DATA_COMPLETE, responses, now, None, status)

    def notice_of_completion(self, condition, delivery, responses, now, fault_loc, status=None):
        self.condition = condition
        self.release()
        self.nak.stop()
        self.check.stop()
        self.keep_alive.stop()
        self.inactivity.stop()
        fs = self.entity.fs
        if status is None:
            status = FILE_DISCARDED
            dest = self.meta["dest_name"] if self.meta else None
            try:
                if fs.exists(self.part):
                    if self.remote.keep_incomplete and dest:
                        fs.rename(self.part, dest)
                        status = FILE_RETAINED
                    else:
                        fs.delete(self.part)
            except OSError:
                status = FILE_DISCARDED_FILESTORE
            if not self.meta or not self.meta["dest_name"]:
                status = FILE_STATUS_UNREPORTED
        self.indicate(
            "finished",
            role="R",
            condition=condition,
            delivery=delivery,
            file_status=status,
            responses=list(responses),
            progress=self.progress_of(),
            size=self.eof[1] if self.eof else (self.meta["size"] if self.meta else 0),
            dest_name=self.meta["dest_name"] if self.meta else None,
            origin=self.origin,
        )
        self.entity.receiver_finished(self, condition, now)
        fin = FinishedPdu(self.header, condition, delivery, status, responses, fault_loc)
        if self.mode == ACKNOWLEDGED:
            self.finished = fin.pack()
            self.emit(self.finished)
            self.state_ = WAIT_FIN_ACK
            self.ack.start(now, reset_count=True)
            self.save(force=True)
        else:
            if self.meta is not None and self.meta["closure"]:
                self.emit(fin.pack())
            self.close()

    def cancel(self, condition, now, fault_location):
        if self.done:
            return
        if self.state_ == WAIT_FIN_ACK:
            self.abandon(condition)
            return
        self.notice_of_completion(condition, DATA_INCOMPLETE, (), now, fault_location)

    # -- timers ----------------------------------------------------------------------------
    def poll(self, now):
        if self.done or self.suspended:
            return
        if self.state_ == WAIT_FIN_ACK:
            if self.ack.expired(now):
                if self.ack.expire(now):
                    self.indicate(
                        "fault",
                        condition=POSITIVE_ACK_LIMIT_REACHED,
                        handler=4,
                        progress=self.progress_of(),
                    )
                    self.abandon(POSITIVE_ACK_LIMIT_REACHED)
                else:
                    self.entity.stats["finished_resent"] += 1
                    self.emit(self.finished)
            return
        if self.nak.expired(now):
            if self.missing():
                if self.nak.expire(now):
                    self.fault(NAK_LIMIT_REACHED, now)
                    return
                # NAK pacing: a gap asked for less than an interval ago is not asked again yet
                # (its data may still be coming): no retransmission of what is on its way
                self._nak_all(now, settle=self.remote.nak_interval * 0.5)
            else:
                self.nak.stop()
        if self.check.expired(now):
            if not self._check_done(now):
                if self.check.expire(now):
                    self.fault(CHECK_LIMIT_REACHED, now)
                    return
        if self.keep_alive.expired(now):
            self.keep_alive.start(now)
            self._keep_alive()
        if self.inactivity.expired(now):
            self.inactivity.start(now)
            self.fault(INACTIVITY_DETECTED, now)

    def resume(self, now):
        if not Transaction.resume(self, now):
            return False
        if self.state_ == RECEIVING and self.eof is not None and not self._check_done(now):
            if self.mode == ACKNOWLEDGED:
                self._nak_all(now)
                self.nak.start(now)
        return True

    def state(self):
        from obsw.cfdp.persist import receiver_state

        return receiver_state(self)

    @classmethod
    def restored(cls, entity, st, remote, now):
        from obsw.cfdp.persist import restore_receiver

        return restore_receiver(cls, entity, st, remote, now)
