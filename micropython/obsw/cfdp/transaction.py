"""What sending and receiving transactions share: identity, timers, fault handling, suspend,
resume, indications and the persisted state."""

import json

from obsw.cfdp.defs import (
    HANDLER_ABANDON,
    HANDLER_IGNORE,
    HANDLER_SUSPEND,
    NO_ERROR,
    SUSPEND_REQUEST_RECEIVED,
    TLV_FAULT_HANDLER,
)


class Transaction:
    """Base of Sender and Receiver. ``entity`` is the CfdpEntity that owns it."""

    role = "?"

    def __init__(self, entity, tid, remote, mode):
        self.entity = entity
        self.tid = tid
        self.remote = remote
        self.mode = mode
        self.suspended = False
        self.done = False
        self.condition = NO_ERROR
        self.overrides = {}
        self.timers = ()
        self.messages = []  # messages to user carried by this transaction
        self.origin = None  # originating transaction id (proxy operations)
        self._saved_at = 0
        self.proxy_put = False  # a sender started for a Proxy Put Request

    # -- plumbing -------------------------------------------------------------------------
    def emit(self, pdu):
        self.entity.queue_pdu(self.remote.entity_id, pdu)

    def indicate(self, kind, **info):
        self.entity.indicate(kind, self.tid, **info)

    def set_overrides(self, options):
        for t in options:
            if t.tlv_type == TLV_FAULT_HANDLER:
                self.overrides[t.condition] = t.handler

    def deadline(self):
        best = None
        for t in self.timers:
            d = t.deadline
            if d is not None and (best is None or d < best):
                best = d
        return best

    # -- faults, suspend, resume ----------------------------------------------------------
    def fault(self, condition, now):
        """Declare a fault; True when its handler says to ignore it and carry on."""
        handler = self.entity.mib.handler(condition, self.overrides)
        self.indicate("fault", condition=condition, handler=handler, progress=self.progress_of())
        if handler == HANDLER_IGNORE:
            return True
        if handler == HANDLER_SUSPEND:
            self.suspend(now, condition)
        elif handler == HANDLER_ABANDON:
            self.abandon(condition)
        else:
            self.cancel(condition, now, self.entity.mib.entity_id)
        return False

    def suspend(self, now, condition=SUSPEND_REQUEST_RECEIVED):
        if self.suspended or self.done:
            return False
        self.suspended = True
        for t in self.timers:
            t.suspend(now)
        self.indicate("suspended", condition=condition)
        self.save(force=True)
        return True

    def resume(self, now):
        if not self.suspended or self.done:
            return False
        self.suspended = False
        for t in self.timers:
            t.resume(now)
        self.indicate("resumed", progress=self.progress_of())
        self.save(force=True)
        return True

    def abandon(self, condition):
        self.condition = condition
        self.indicate("abandoned", condition=condition, progress=self.progress_of())
        self.close()

    def close(self):
        """The transaction is over: release resources and forget its persisted state."""
        self.done = True
        self.release()
        self.entity.forget(self)

    def release(self):
        pass

    def cancel(self, condition, now, fault_location):
        raise NotImplementedError

    def progress_of(self):
        return 0

    # -- persistence ----------------------------------------------------------------------
    def sync_data(self):
        """Put the data this transaction wrote on the medium (before its state claims it)."""

    def save(self, force=False):
        ent = self.entity
        if not ent.persist or self.done:
            return
        self.sync_data()  # durability order: the data first, then the progress that claims it
        st = self.state()
        st["role"] = self.role
        st["tid"] = list(self.tid)
        st["mode"] = self.mode
        st["suspended"] = self.suspended
        st["condition"] = self.condition
        st["overrides"] = [[k, self.overrides[k]] for k in self.overrides]
        st["timers"] = [t.state() for t in self.timers]
        st["origin"] = list(self.origin) if self.origin else None
        st["proxy_put"] = self.proxy_put
        ent.state_fs.write_atomic(ent.state_name(self.tid, self.role), json.dumps(st).encode())

    def restore_common(self, st, now):
        self.suspended = st["suspended"]
        self.condition = st["condition"]
        for k, v in st["overrides"]:
            self.overrides[k] = v
        for t, s in zip(self.timers, st["timers"]):
            t.restore(s, now)
            if self.suspended:
                t.suspend(now)
        if st.get("origin"):
            self.origin = tuple(st["origin"])
        self.proxy_put = st.get("proxy_put", False)

    def report(self):
        return {
            "tid": self.tid,
            "role": self.role,
            "mode": self.mode,
            "suspended": self.suspended,
            "condition": self.condition,
            "progress": self.progress_of(),
            "done": self.done,
        }
