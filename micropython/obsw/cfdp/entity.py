"""The CFDP entity: a sans-I/O state machine. PDUs, user requests and the time go in; PDUs to
send, indications and the next deadline come out.

    ent = CfdpEntity(mib, filestore)
    tid = ent.put(2, "a.bin", "b.bin", now=t)
    for dest, pdu in ent.transmit(t): link.send(dest, pdu)
    ent.receive(pdu_bytes, t); ent.poll(t); ent.next_deadline(); ent.pop_indications()
"""

import json

from obsw.cfdp.defs import (
    ACKNOWLEDGED,
    CANCEL_REQUEST_RECEIVED,
    DIR_EOF,
    DIR_FINISHED,
    DIR_METADATA,
    FILE_DIRECTIVE,
    FILESTORE_REJECTION,
    STATUS_ACTIVE,
    STATUS_TERMINATED,
    STATUS_UNRECOGNIZED,
    TOWARD_RECEIVER,
    TOWARD_SENDER,
    CfdpError,
)
from obsw.cfdp.pdu import decode_pdu
from obsw.cfdp.pdu.ack import AckPdu
from obsw.cfdp.receiver import Receiver
from obsw.cfdp.sender import Sender


class Indication:
    """A CFDP indication to the user: ``kind``, the transaction id and details in ``info``."""

    def __init__(self, kind, tid, info):
        self.kind = kind
        self.tid = tid
        self.info = info

    def __repr__(self):
        return "Indication(%s, %r, %r)" % (self.kind, self.tid, self.info)


_STAT_KEYS = (
    "pdus_sent",
    "pdus_received",
    "file_bytes_sent",
    "retransmitted_pdus",
    "retransmitted_bytes",
    "naks_sent",
    "naks_received",
    "eof_resent",
    "finished_resent",
    "decode_errors",
    "misrouted",
    "oversize",
    "refused",
    "internal_errors",
    "filestore_errors",
    "state_rejected",
)


class CfdpEntity:
    """One CFDP entity: any number of concurrent sending and receiving transactions."""

    def __init__(
        self, mib, filestore, *, persist=False, work_dir=".cfdp", checkpoint=262144, state=None
    ):
        self.mib = mib
        self.fs = filestore
        self.persist = persist
        self.work_dir = work_dir  # partial files and listings, in the filestore
        # the persisted state (transactions, sequence number, remote copies): in ``state``, a
        # filestore of its own that the ground cannot write to, else beside the work files
        self.state_fs = filestore if state is None else state
        self.state_dir = work_dir if state is None else "cfdp"
        self._state_ready = False
        self.checkpoint_bytes = checkpoint
        self.tx = {}  # (tid, role) -> Transaction
        self.done = {}  # (tid, role) -> (mode, condition) of finished ones, for late PDUs
        self._done_order = []
        self._out = []
        self._ind = []
        self.seq = 1
        self.stats = {}
        for k in _STAT_KEYS:
            self.stats[k] = 0
        self._work_ready = False
        self.proxy = {}  # our request tid -> state of a proxy put we asked for
        self.user_messages = None  # optional callable(tx, messages) for user-defined messages
        # the last file data PDU's fixed header (receive's fast path): (flags octet, the
        # octets after the length, header length, transaction key, receiver), or None
        self._fd_fast = None

    # -- names in the filestore ------------------------------------------------------------
    def work_name(self, name):
        if not self._work_ready:
            if not self.fs.is_dir(self.work_dir):
                self.fs.mkdir(self.work_dir)
            self._work_ready = True
        return self.work_dir + "/" + name

    def state_path(self, name):
        """The name of the state file ``name`` in the state filestore (its folder made)."""
        if not self._state_ready:
            if not self.state_fs.is_dir(self.state_dir):
                self.state_fs.mkdir(self.state_dir)
            self._state_ready = True
        return self.state_dir + "/" + name

    def state_name(self, tid, role):
        return self.state_path("%s-%d-%d.json" % (role, tid[0], tid[1]))

    def set_aside(self, name, why):
        """A state file that cannot be used: renamed ``bad-NAME`` (kept for the ground to look
        at, never read again) with a ``state_rejected`` indication; the unit starts clean."""
        fs = self.state_fs
        path = self.state_dir + "/" + name
        try:
            fs.rename(path, self.state_dir + "/bad-" + name)
        except OSError:
            try:
                fs.delete(path)
            except OSError:
                pass
        self.stats["state_rejected"] += 1
        self.indicate("state_rejected", None, name=name, reason=why)

    # -- outputs ---------------------------------------------------------------------------
    def queue_pdu(self, dest, pdu):
        self._out.append((dest, pdu))

    def indicate(self, kind, tid, **info):
        self._ind.append(Indication(kind, tid, info))

    def pop_indications(self):
        out = self._ind
        self._ind = []
        return out

    def transmit(self, now, limit=64):
        """PDUs to send now as (destination entity id, bytes): every pending directive, then up
        to ``limit`` file data PDUs shared round-robin between sending transactions."""
        out = self._out
        self._out = []
        senders = [t for t in self.tx.values() if t.role == "S" and t.has_data()]
        n = 0
        while senders and n < limit:
            for s in list(senders):
                try:
                    p = s.next_pdu(now)
                except Exception as e:  # the file went away or a defect: that transaction only
                    self.failed(s, e, now)
                    p = None
                if p is None:
                    senders.remove(s)
                else:
                    out.append((s.remote.entity_id, p))
                    n += 1
        if self._out:
            out.extend(self._out)
            self._out = []
        self.stats["pdus_sent"] += len(out)
        return out

    def pending(self):
        """True when transmit() has something to give right now."""
        if self._out:
            return True
        for t in self.tx.values():
            if t.role == "S" and t.has_data():
                return True
        return False

    def next_deadline(self):
        best = None
        for t in self.tx.values():
            d = t.deadline()
            if d is not None and (best is None or d < best):
                best = d
        return best

    def busy(self):
        return bool(self.tx)

    # -- user requests ---------------------------------------------------------------------
    def _next_seq(self):
        seq = self.seq
        self.seq = seq + 1
        if self.seq >> (8 * self.mib.seq_len):
            self.seq = 1
        if self.persist:
            self.state_fs.write_atomic(self.state_path("seq"), str(self.seq).encode())
        return seq

    def put(
        self,
        dest_id,
        source_name=None,
        dest_name=None,
        *,
        mode=None,
        closure=None,
        messages=(),
        filestore_requests=(),
        fault_overrides=(),
        flow_label=None,
        seg_ctrl=False,
        checksum=None,
        now=0,
        origin=None,
    ):
        """Put.request: start sending a file (or only the options); returns the transaction id."""
        remote = self.mib.remote(dest_id)
        if remote is None:
            raise ValueError("no MIB entry for remote entity %d" % dest_id)
        options = list(filestore_requests) + list(messages) + list(fault_overrides)
        if flow_label is not None:
            options.append(flow_label)
        req = {
            "mode": remote.mode if mode is None else mode,
            "closure": remote.closure if closure is None else closure,
            "source_name": source_name,
            "dest_name": dest_name or source_name,
            "checksum": remote.checksum if checksum is None else checksum,
            "seg_ctrl": seg_ctrl,
            "options": options,
        }
        if source_name and not self.fs.exists(source_name):
            raise ValueError("no such file to put: %s" % source_name)
        tid = (self.mib.entity_id, self._next_seq())
        tx = Sender(self, tid, remote, req, now)
        tx.messages = list(messages)
        tx.origin = origin
        self.tx[(tid, "S")] = tx
        self.indicate("transaction", tid, role="S", dest_id=dest_id, size=tx.size)
        tx.save(force=True)
        return tid

    def find(self, tid):
        return self.tx.get((tid, "S")) or self.tx.get((tid, "R"))

    def cancel(self, tid, now):
        tx = self.find(tid)
        if tx is None:
            return False
        tx.cancel(CANCEL_REQUEST_RECEIVED, now, self.mib.entity_id)
        return True

    def suspend(self, tid, now):
        tx = self.find(tid)
        return tx.suspend(now) if tx is not None else False

    def resume(self, tid, now):
        tx = self.find(tid)
        return tx.resume(now) if tx is not None else False

    def prompt(self, tid, kind, now):
        tx = self.tx.get((tid, "S"))
        return tx.prompt(kind, now) if tx is not None else False

    def report(self, tid):
        """Report.request: the transaction's status as a dict (also given as an indication)."""
        tx = self.find(tid)
        if tx is not None:
            rep = tx.report()
            rep["status"] = STATUS_ACTIVE
        else:
            for role in ("S", "R"):
                d = self.done.get((tid, role))
                if d is not None:
                    rep = {"tid": tid, "role": role, "mode": d[0], "condition": d[1]}
                    rep["status"] = STATUS_TERMINATED
                    break
            else:
                rep = {"tid": tid, "status": STATUS_UNRECOGNIZED}
        self.indicate("report", tid, report=rep)
        return rep

    # -- incoming PDUs ---------------------------------------------------------------------
    def receive(self, buf, now):
        """Take one PDU from the link. Malformed or misrouted PDUs are counted, never raised.
        Returns the decoded PDU, or None (also for the file data taken on the fast path)."""
        fast = self._fd_fast
        if fast is not None and len(buf) > fast[2] + 4 and buf[0] == fast[0]:
            hl = fast[2]
            end = hl + ((buf[1] << 8) | buf[2])
            if hl + 4 < end <= len(buf) and buf[3:hl] == fast[1]:
                tx = fast[4]
                if self.tx.get(fast[3]) is tx and not tx.done:
                    # a file data PDU of the transaction the last one belonged to: the same
                    # header octets, already checked and routed; straight to the receiver
                    self.stats["pdus_received"] += 1
                    offset = (buf[hl] << 24) | (buf[hl + 1] << 16) | (buf[hl + 2] << 8)
                    offset |= buf[hl + 3]
                    try:
                        tx.on_file_data_pdu(offset, memoryview(buf)[hl + 4 : end], now)
                    except Exception as e:  # as below: that transaction only
                        self._fd_fast = None
                        self.failed(tx, e, now)
                    return None
                self._fd_fast = None
        try:
            pdu = decode_pdu(buf)
        except CfdpError:
            self.stats["decode_errors"] += 1
            return None
        self.stats["pdus_received"] += 1
        h = pdu.header
        me = self.mib.entity_id
        tid = (h.source, h.seq)
        if h.direction == TOWARD_RECEIVER:
            if h.dest != me:
                self.stats["misrouted"] += 1
                return None
            tx = self.tx.get((tid, "R"))
            if tx is None:
                code = pdu.CODE
                if (tid, "R") in self.done:
                    if code == DIR_EOF and h.mode == ACKNOWLEDGED:
                        self._ack_late(h, DIR_EOF, pdu.condition)
                    return None
                if code not in (None, DIR_METADATA, DIR_EOF):
                    return None
                remote = self.mib.remote(h.source)
                if remote is None:
                    self.stats["misrouted"] += 1
                    return None
                if len(self.tx) >= self.mib.max_transactions:
                    self.stats["refused"] += 1  # the sender's timers will try again
                    return None
                tx = Receiver(self, tid, remote, h, now)
                self.tx[(tid, "R")] = tx
                self.indicate("transaction", tid, role="R", source_id=h.source)
        else:
            if h.source != me:
                self.stats["misrouted"] += 1
                return None
            tx = self.tx.get((tid, "S"))
            if tx is None:
                if pdu.CODE == DIR_FINISHED and h.mode == ACKNOWLEDGED:
                    self._ack_late(h, DIR_FINISHED, pdu.condition)
                return None
        try:
            tx.on_pdu(pdu, now)
        except Exception as e:  # must not stop the entity: that transaction only
            self.failed(tx, e, now)
            return None
        if pdu.CODE is None and h.direction == TOWARD_RECEIVER:
            self._remember_file_data(buf, h, tid, tx)
        return pdu

    def failed(self, tx, exc, now):
        """A transaction's step raised: a filestore error (the file was deleted or cannot be
        read) is the standard's filestore rejection fault, handled as the MIB says (cancel:
        the peer is told); anything else is a defect and abandons it. Never raises."""
        if isinstance(exc, OSError):
            self.stats["filestore_errors"] += 1
            try:
                if not tx.done:
                    tx.fault(FILESTORE_REJECTION, now)
                return
            except Exception:
                pass  # the fault's own steps need the file too: abandon
        else:
            self.stats["internal_errors"] += 1
        try:
            if not tx.done:
                tx.abandon(FILESTORE_REJECTION)
        except Exception:
            self.forget(tx)

    def _remember_file_data(self, buf, h, tid, tx):
        """Keep a file data PDU's header for the fast path of the next ones of its
        transaction: only the plain kind (32-bit offsets, no CRC, no segment metadata)."""
        if h.crc or h.large or h.seg_meta:
            self._fd_fast = None
            return
        hl = 4 + 2 * h.eid_len + h.seq_len
        self._fd_fast = (buf[0], bytes(buf[3:hl]), hl, (tid, "R"), tx)

    def _ack_late(self, h, directive, condition):
        """ACK a repeated EOF or Finished of a transaction that is already over here."""
        known = (h.transaction_id(), "R" if directive == DIR_EOF else "S") in self.done
        hdr = h.copy(
            pdu_type=FILE_DIRECTIVE,
            direction=TOWARD_SENDER if directive == DIR_EOF else TOWARD_RECEIVER,
        )
        st = STATUS_TERMINATED if known else STATUS_UNRECOGNIZED
        self.queue_pdu(
            h.source if directive == DIR_EOF else h.dest,
            AckPdu(hdr, directive, condition, st).pack(),
        )

    def poll(self, now):
        """Run the timers of every transaction."""
        for tx in list(self.tx.values()):
            try:
                tx.poll(now)
            except Exception as e:
                self.failed(tx, e, now)

    # -- transaction ends ------------------------------------------------------------------
    def forget(self, tx):
        key = (tx.tid, tx.role)
        if self.tx.get(key) is tx:
            del self.tx[key]
        self.done[key] = (tx.mode, tx.condition)
        self._done_order.append(key)
        if len(self._done_order) > 64:
            self.done.pop(self._done_order.pop(0), None)
        if self.persist:
            try:
                name = self.state_name(tx.tid, tx.role)
                if self.state_fs.exists(name):
                    self.state_fs.delete(name)
            except OSError:
                pass

    def sender_finished(self, tx, condition, delivery, file_status, responses, now):
        from obsw.cfdp.proxy import on_sender_finished

        on_sender_finished(self, tx, condition, delivery, file_status, responses, now)

    def receiver_finished(self, tx, condition, now):
        from obsw.cfdp.proxy import on_receiver_finished

        on_receiver_finished(self, tx, condition, now)

    def note_messages(self, tx):
        from obsw.cfdp.proxy import note_origin

        note_origin(tx)

    # -- restart ---------------------------------------------------------------------------
    def restore(self, now):
        """Reload transactions persisted before a restart; returns how many came back. A state
        file that does not check (``obsw.cfdp.persist.check_state``) or does not rebuild is set
        aside (``set_aside``): no content of a state file can stop the entity from starting."""
        from obsw.cfdp.persist import StateError, check_state

        fs = self.state_fs
        if not fs.is_dir(self.state_dir):
            return 0
        self._state_ready = True
        self.load_seq()
        n = 0
        for name in fs.listdir(self.state_dir):
            if not name.endswith(".json") or name[:2] not in ("S-", "R-"):
                continue
            try:
                st = json.loads(fs.read_bytes(self.state_dir + "/" + name).decode())
                check_state(st)
                tid = (st["tid"][0], st["tid"][1])
                role = st["role"]
                if name != "%s-%d-%d.json" % (role, tid[0], tid[1]):
                    raise StateError("its content is transaction %s-%d-%d" % ((role,) + tid))
                remote = self.mib.remote(tid[0] if role == "R" else st["dest_id"])
                if remote is None:
                    raise StateError("no MIB entry for its remote entity")
                cls = Receiver if role == "R" else Sender
                tx = cls.restored(self, st, remote, now)
            except Exception as e:  # bad JSON, a bad field, a file gone: set aside, go on
                self.set_aside(name, "%s: %s" % (type(e).__name__, e))
                continue
            self.tx[(tid, role)] = tx
            self.indicate("restored", tid, role=role, progress=tx.progress_of())
            n += 1
        return n

    def load_seq(self):
        """Continue the transaction sequence numbers persisted by an earlier run."""
        name = self.state_dir + "/seq"
        try:
            if not self.state_fs.exists(name):
                return
            seq = int(self.state_fs.read_bytes(name).decode())
            if not 0 < seq < 1 << (8 * self.mib.seq_len):
                raise ValueError("sequence number %d out of range" % seq)
            self.seq = seq
        except (OSError, ValueError, UnicodeError) as e:
            self.set_aside("seq", "%s: %s" % (type(e).__name__, e))

    def statuses(self):
        return [t.report() for t in self.tx.values()]
