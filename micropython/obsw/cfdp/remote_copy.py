"""The "remote file copy" component of the CFDP entity: copies to and from the ground for PUS
service 23, on the interaction layer.

``REMOTE_COPY`` is the interface, declared once; ``RemoteCopy`` is the provider's
implementation wrapping a ``CfdpEntity``. ``put_to_ground`` sends an onboard file with a put
request; ``get_from_ground`` asks the ground entity for a file with a proxy put request, and
the transaction that brings it is recognised by its originating transaction ID. Both are
asynchronous operations: the caller's ``Pending`` gets the transfer's status record as
status updates (``state``, ``bytes`` done of ``size``) and ends with the last record, or fails
with a ``ComponentError`` whose code is the final state. ``suspend``, ``resume``, ``cancel``
and ``status`` take the transfer key the records carry (``"entity:sequence"`` of the
request). Progress is also published as events. Records persist in the entity's work
directory (written atomically), so after a restart ``status`` still knows every transfer and
follows the restored CFDP transactions to their end.

Whoever drives the entity hands every indication to ``indication(ind)`` (e.g. as
``UdpEntity.on_indication``) and calls ``poll(now)`` now and then for progress.
"""

import json

from obsw.cfdp import msgs
from obsw.cfdp.defs import DATA_COMPLETE, NO_ERROR
from obsw.compat import const
from obsw.il.errors import ComponentError
from obsw.il.interface import DATA, INFO, LOW, Attribute, Event, Interface, Operation

REMOTE_COPY_NAME = "RemoteFileCopy"
REMOTE_COPY_ID = const(0x23)

# transfer states
REQUESTED = "requested"  # a get asked for, no data yet
ACTIVE = "active"
SUSPENDED = "suspended"
COMPLETED = "completed"
FAILED = "failed"
CANCELLED = "cancelled"
FINAL = (COMPLETED, FAILED, CANCELLED)

# ComponentError codes
NO_SUCH_FILE = "NO_SUCH_FILE"
UNKNOWN_ENTITY = "UNKNOWN_ENTITY"
UNKNOWN_TRANSFER = "UNKNOWN_TRANSFER"
NOT_ACTIVE = "NOT_ACTIVE"

REMOTE_COPY = Interface(
    REMOTE_COPY_NAME,
    REMOTE_COPY_ID,
    [
        Attribute("transfers", 1, DATA, description="status records of the transfers known"),
        Operation("put_to_ground", 2, ("source", "dest", "entity"), asynchronous=True),
        Operation("get_from_ground", 3, ("source", "dest", "entity"), asynchronous=True),
        Operation("suspend", 4, ("transfer",), returns="record"),
        Operation("resume", 5, ("transfer",), returns="record"),
        Operation("cancel", 6, ("transfer",), returns="record"),
        Operation("status", 7, ("transfer",), returns="record"),
        Event("copy_progress", 16, INFO, fields=("transfer", "state", "bytes", "size")),
        Event("copy_finished", 17, INFO, fields=("transfer", "direction", "size")),
        Event("copy_failed", 18, LOW, fields=("transfer", "state", "condition")),
    ],
    description="file copies between the onboard filestore and the ground, over CFDP",
)


_RECORD = {"transfer": str, "direction": str, "state": str, "bytes": int, "size": int,
           "tid": list, "condition": int}  # fmt: skip


def key_of(tid):
    return "%d:%d" % (tid[0], tid[1])


class RemoteCopy:
    """The provider's implementation (see the module text)."""

    def __init__(self, entity, state_name="remote-copy.json", keep=64):
        self.entity = entity
        self.state_name = state_name
        self.keep = keep  # finished records kept for status requests
        self.now = 0.0
        self.provider = None
        self.records = {}  # transfer key -> record dict
        self.jobs = {}  # transfer key -> Job (this run only)
        self._reported = {}  # transfer key -> bytes last reported
        self._load()

    def il_bind(self, provider):
        self.provider = provider

    @property
    def transfers(self):
        return [dict(r) for r in self.records.values()]

    # -------------------------------------------------------------------------- persistence

    def _path(self):
        return self.entity.state_path(self.state_name)

    def _load(self):
        ent = self.entity
        fs = ent.state_fs
        name = ent.state_dir + "/" + self.state_name
        try:
            if not fs.exists(name):
                return
            recs = json.loads(fs.read_bytes(name).decode())
            if not isinstance(recs, list):
                raise ValueError("expected a list of records")
            for r in recs:
                for k in _RECORD:
                    if not isinstance(r.get(k), _RECORD[k]):
                        raise ValueError("record field %s: %r" % (k, r.get(k)))
                self.records[r["transfer"]] = r
        except Exception as e:  # bad JSON or a bad record: set aside, start clean
            self.records = {}
            ent.set_aside(self.state_name, "%s: %s" % (type(e).__name__, e))

    def _save(self):
        recs = list(self.records.values())
        done = [r for r in recs if r["state"] in FINAL]
        for r in done[: max(0, len(done) - self.keep)]:
            del self.records[r["transfer"]]
        try:
            data = json.dumps(list(self.records.values())).encode()
            self.entity.state_fs.write_atomic(self._path(), data)
        except OSError:
            pass

    # -------------------------------------------------------------------------- operations

    def _new(self, job, direction, tid, source, dest, entity, size, state):
        key = key_of(tid)
        rec = {
            "transfer": key,
            "direction": direction,
            "source": source,
            "dest": dest,
            "entity": entity,
            "state": state,
            "bytes": 0,
            "size": size,
            "condition": NO_ERROR,
            "tid": list(tid),
            "rx": None,
        }
        self.records[key] = rec
        self.jobs[key] = job
        self._save()
        job.update(dict(rec))
        return rec

    def _check_entity(self, entity):
        if self.entity.mib.remote(entity) is None:
            raise ComponentError(UNKNOWN_ENTITY, "no CFDP entity %r in the MIB" % (entity,))

    def put_to_ground(self, job, source, dest, entity):
        self._check_entity(entity)
        ent = self.entity
        if not ent.fs.exists(source) or ent.fs.is_dir(source):
            raise ComponentError(NO_SUCH_FILE, "no file %s to send" % source)
        try:
            tid = ent.put(entity, source, dest, now=self.now)
        except (ValueError, OSError) as e:
            raise ComponentError(NO_SUCH_FILE, str(e)) from None
        self._new(job, "put", tid, source, dest, entity, ent.fs.size(source), ACTIVE)

    def get_from_ground(self, job, source, dest, entity):
        self._check_entity(entity)
        ent = self.entity
        req = msgs.proxy_put_request(ent.mib.entity_id, source, dest)
        tid = ent.put(entity, messages=[req], now=self.now)
        self._new(job, "get", tid, source, dest, entity, 0, REQUESTED)

    def _record(self, transfer):
        rec = self.records.get(transfer)
        if rec is None:
            raise ComponentError(UNKNOWN_TRANSFER, "no transfer %r" % (transfer,))
        return rec

    def _data_tid(self, rec):
        """The CFDP transaction that carries the file, or None (a get not yet answered)."""
        if rec["direction"] == "put":
            return tuple(rec["tid"])
        return tuple(rec["rx"]) if rec["rx"] else None

    def suspend(self, transfer):
        rec = self._record(transfer)
        if rec["state"] != ACTIVE:
            raise ComponentError(NOT_ACTIVE, "transfer %s is %s" % (transfer, rec["state"]))
        tid = self._data_tid(rec)
        self.entity.suspend(tid, self.now)
        # the other end suspends too, or its inactivity timer would end the transaction
        self._ask(rec, msgs.remote_suspend_request(tid))
        self._set(rec, SUSPENDED)
        return dict(rec)

    def resume(self, transfer):
        rec = self._record(transfer)
        if rec["state"] != SUSPENDED:
            raise ComponentError(NOT_ACTIVE, "transfer %s is %s" % (transfer, rec["state"]))
        tid = self._data_tid(rec)
        self.entity.resume(tid, self.now)
        self._ask(rec, msgs.remote_resume_request(tid))
        self._set(rec, ACTIVE)
        return dict(rec)

    def cancel(self, transfer):
        rec = self._record(transfer)
        if rec["state"] in FINAL:
            return dict(rec)
        tid = self._data_tid(rec)
        if tid is not None:
            self.entity.cancel(tid, self.now)
        if rec["direction"] == "get":
            self._ask(
                rec,
                msgs.proxy_put_cancel(),
                msgs.originating_transaction_id(tuple(rec["tid"])),
            )
        self._set(rec, CANCELLED)
        return dict(rec)

    def status(self, transfer):
        rec = self._record(transfer)
        self._progress(rec)
        return dict(rec)

    def _ask(self, rec, *messages):
        try:
            self.entity.put(rec["entity"], messages=list(messages), now=self.now)
        except ValueError:
            pass

    # -------------------------------------------------------------------------- following

    def _set(self, rec, state, condition=None):
        if rec["state"] == state and condition is None:
            return
        rec["state"] = state
        if condition is not None:
            rec["condition"] = condition
        self._save()
        key = rec["transfer"]
        job = self.jobs.get(key)
        p = self.provider
        if state == COMPLETED:
            rec["bytes"] = rec["size"]
            if job is not None:
                job.succeed(dict(rec))
            if p is not None:
                p.emit(
                    "copy_finished",
                    {"transfer": key, "direction": rec["direction"], "size": rec["size"]},
                )
        elif state in (FAILED, CANCELLED):
            if job is not None:
                job.fail(ComponentError(state.upper(), "transfer %s %s" % (key, state), dict(rec)))
            if p is not None:
                p.emit(
                    "copy_failed", {"transfer": key, "state": state, "condition": rec["condition"]}
                )
        else:
            if job is not None:
                job.update(dict(rec))
            if p is not None:
                p.emit("copy_progress", self._event(rec))
        if state in FINAL:
            self.jobs.pop(key, None)
            self._reported.pop(key, None)

    def _event(self, rec):
        return {
            "transfer": rec["transfer"],
            "state": rec["state"],
            "bytes": rec["bytes"],
            "size": rec["size"],
        }

    def _find(self, tid, field):
        want = list(tid)
        for rec in self.records.values():
            if rec[field] == want and rec["state"] not in FINAL:
                return rec
        return None

    def indication(self, ind):
        """Follow one indication of the entity."""
        kind = ind.kind
        info = ind.info
        if kind == "metadata":
            tx = self.entity.find(ind.tid)
            origin = tx.origin if tx is not None else None
            rec = self._find(origin, "tid") if origin and info.get("source_name") else None
            if rec is not None and rec["direction"] == "get":
                rec["rx"] = list(ind.tid)
                rec["size"] = info.get("size", 0)
                self._set(rec, ACTIVE)
        elif kind == "finished":
            if info.get("role") == "S":
                rec = self._find(ind.tid, "tid")
                if rec is not None and rec["direction"] == "put":
                    self._end(rec, info)
                elif rec is not None and info.get("condition") != NO_ERROR:
                    self._set(rec, FAILED, info.get("condition"))
            else:
                rec = self._find(ind.tid, "rx")  # not the metadata-only responses
                if rec is not None:
                    self._end(rec, info)
        elif kind == "proxy_response":
            if info.get("message") == msgs.PROXY_PUT_RESPONSE and info.get("origin"):
                rec = self._find(info["origin"], "tid")
                f = info.get("fields") or {}
                if rec is not None and f.get("condition", NO_ERROR) != NO_ERROR:
                    self._set(rec, FAILED, f["condition"])
        elif kind == "abandoned":
            rec = self._find(ind.tid, "tid") or self._find(ind.tid, "rx")
            if rec is not None:
                self._set(rec, FAILED, info.get("condition"))
        elif kind in ("suspended", "resumed"):
            rec = self._find(ind.tid, "tid") or self._find(ind.tid, "rx")
            if rec is not None and rec["state"] != REQUESTED:
                self._set(rec, SUSPENDED if kind == "suspended" else ACTIVE)

    def _end(self, rec, info):
        cond = info.get("condition", NO_ERROR)
        if cond == NO_ERROR and info.get("delivery", DATA_COMPLETE) == DATA_COMPLETE:
            self._set(rec, COMPLETED, cond)
        elif rec["state"] != CANCELLED:
            self._set(rec, FAILED, cond)

    def _progress(self, rec):
        tid = self._data_tid(rec)
        tx = self.entity.find(tid) if tid is not None else None
        if tx is not None:
            rec["bytes"] = tx.progress_of()
            size = getattr(tx, "size", None)
            if size:
                rec["size"] = size

    def poll(self, now):
        """Bring the progress of active transfers up to date; report what changed."""
        self.now = now
        for key, rec in self.records.items():
            if rec["state"] != ACTIVE:
                continue
            self._progress(rec)
            if self._reported.get(key) != rec["bytes"]:
                self._reported[key] = rec["bytes"]
                job = self.jobs.get(key)
                if job is not None:
                    job.update(dict(rec))
                if self.provider is not None:
                    self.provider.emit("copy_progress", self._event(rec))
