"""ST[15] on-board storage and retrieval: packet stores filled while out of contact.

Every TM of the application process passes its TM pipeline (``tm_stores``); each packet store whose
storage function is enabled keeps the packets its storage-control configuration selects
(report types per APID, housekeeping structure IDs, blocked event IDs; ECSS-E-ST-70-41C
6.15). Stores are circular (the oldest packets make room) or bounded (new packets are
refused when full). Retrieval sends the stored packets unchanged on the store's virtual
channel (``ApplicationProcess.play``): by time range (TC[15,9]), by storage sequence numbers
(TC[15,7], project-defined after PUS-A's packet range downlink) or as the open retrieval,
which follows the store from a start time tag as packets arrive. ``rate`` packets per store
go out per cycle of the application process. TC[15,24] copies a time window of one store into
another, and diagnostic reports have their storage control as housekeeping reports do
(``obsw.pus.services.s15_copy``). Store configuration and control persist in the
context store; their content in log files of ``filestore`` (``obsw.pus.services
.packet_store``), so the stores survive a restart.
"""

from obsw.pus.messages import (
    FAILURE_REFUSED,
    FAILURE_UNKNOWN_ID,
    SERVICE_STORAGE_AND_RETRIEVAL,
    TC_STORE_ABORT_TIME_RANGE_RETRIEVAL,
    TC_STORE_ADD_BLOCKED_EVENTS,
    TC_STORE_ADD_DIAG_STRUCTURES,
    TC_STORE_ADD_HK_STRUCTURES,
    TC_STORE_ADD_REPORT_TYPES,
    TC_STORE_CHANGE_OPEN_RETRIEVAL_START,
    TC_STORE_CHANGE_VIRTUAL_CHANNEL,
    TC_STORE_COPY_BY_TIME_WINDOW,
    TC_STORE_CREATE,
    TC_STORE_DELETE,
    TC_STORE_DELETE_BLOCKED_EVENTS,
    TC_STORE_DELETE_CONTENT_UP_TO,
    TC_STORE_DELETE_DIAG_STRUCTURES,
    TC_STORE_DELETE_HK_STRUCTURES,
    TC_STORE_DELETE_REPORT_TYPES,
    TC_STORE_DISABLE_STORAGE,
    TC_STORE_ENABLE_STORAGE,
    TC_STORE_MAKE_BOUNDED,
    TC_STORE_MAKE_CIRCULAR,
    TC_STORE_REPORT_BLOCKED_EVENTS,
    TC_STORE_REPORT_CONFIGURATION,
    TC_STORE_REPORT_CONTENT_SUMMARY,
    TC_STORE_REPORT_DIAG_STRUCTURES,
    TC_STORE_REPORT_HK_STRUCTURES,
    TC_STORE_REPORT_REPORT_TYPES,
    TC_STORE_REPORT_STATUS,
    TC_STORE_RESIZE,
    TC_STORE_RESUME_OPEN_RETRIEVAL,
    TC_STORE_RETRIEVE_SEQUENCE_RANGE,
    TC_STORE_START_TIME_RANGE_RETRIEVAL,
    TC_STORE_SUSPEND_OPEN_RETRIEVAL,
    TM_HK_DIAG_REPORT,
    TM_STORE_BLOCKED_EVENTS_REPORT,
    TM_STORE_CONFIGURATION_REPORT,
    TM_STORE_CONTENT_SUMMARY_REPORT,
    TM_STORE_DIAG_STRUCTURES_REPORT,
    TM_STORE_HK_STRUCTURES_REPORT,
    TM_STORE_REPORT_TYPES_REPORT,
    TM_STORE_STATUS_REPORT,
)
from obsw.pus.services.packet_store import BOUNDED, CIRCULAR, PacketStore
from obsw.pus.services.report_types import (
    IdSelection,
    ReportTypes,
    hk_or_event_id,
)
from obsw.pus.services.s01_verification import PusFailure
from obsw.pus.services.s15_copy import CopyAndDiagnostics
from obsw.pus.services.s15_layouts import (
    CHANGE_VC,
    CONFIGURATION,
    EMPTY,
    KIND_NAMES,
    ONE_STORE,
    RESIZE,
    SEQUENCE_RANGE,
    STATUS_REPORT,
    STORE_EVENTS,
    STORE_HK,
    STORE_ID,
    STORE_TYPES,
    STORES,
    SUMMARY_REPORT,
    TIME_AND_STORES,
    TIME_RANGE,
    TIME_TAG,
)


def _failure(code, msg, sid):
    return PusFailure(code, msg, STORE_ID.pack(sid))


class Control:
    """What one store keeps: report types, housekeeping and diagnostic SIDs, blocked event
    IDs."""

    def __init__(self):
        self.types = ReportTypes()
        self.hk = IdSelection()
        self.blocked = IdSelection()
        self.diag = IdSelection()

    def selects(self, h):
        if not self.types.selects(h.apid, h.service, h.subtype):
            return False
        if h.service == TM_HK_DIAG_REPORT[0] and h.subtype == TM_HK_DIAG_REPORT[1]:
            return self.diag.has(h.apid, h.sid())
        kind = hk_or_event_id(h)
        if kind is None:
            return True
        if kind[0] == "hk":
            return self.hk.has(h.apid, kind[1])
        return not self.blocked.listed(h.apid, kind[1])

    def context(self):
        return [
            self.types.context(),
            self.hk.context(),
            self.blocked.context(),
            self.diag.context(),
        ]

    def restore(self, ctx):
        self.types.restore(ctx[0])
        self.hk.restore(ctx[1])
        self.blocked.restore(ctx[2])
        if len(ctx) > 3:  # contexts saved before diagnostic storage control have 3
            self.diag.restore(ctx[3])


class Storage(CopyAndDiagnostics):
    """The service 15 provider (see the module text).

    ``initial`` lists stores as dicts (``id``, ``size``, ``kind``, ``vc``, ``enabled``,
    ``types``: ``{apid: {service: [subtypes]}}``, ``hk``: ``{apid: [SIDs]}``), used when no
    context was saved. ``filestore`` keeps the content; without one it lives in memory only.
    """

    SERVICE = SERVICE_STORAGE_AND_RETRIEVAL
    REPORTS = (
        TM_STORE_REPORT_TYPES_REPORT,
        TM_STORE_CONTENT_SUMMARY_REPORT,
        TM_STORE_STATUS_REPORT,
        TM_STORE_CONFIGURATION_REPORT,
        TM_STORE_HK_STRUCTURES_REPORT,
        TM_STORE_BLOCKED_EVENTS_REPORT,
        TM_STORE_DIAG_STRUCTURES_REPORT,
    )
    NAME = "s15"
    HANDLERS = (
        (TC_STORE_ENABLE_STORAGE, "enable"),
        (TC_STORE_DISABLE_STORAGE, "disable"),
        (TC_STORE_ADD_REPORT_TYPES, "add_types"),
        (TC_STORE_DELETE_REPORT_TYPES, "delete_types"),
        (TC_STORE_REPORT_REPORT_TYPES, "report_types"),
        (TC_STORE_RETRIEVE_SEQUENCE_RANGE, "retrieve_sequence"),
        (TC_STORE_START_TIME_RANGE_RETRIEVAL, "retrieve_time"),
        (TC_STORE_DELETE_CONTENT_UP_TO, "delete_content"),
        (TC_STORE_REPORT_CONTENT_SUMMARY, "report_summary"),
        (TC_STORE_CHANGE_OPEN_RETRIEVAL_START, "change_open_start"),
        (TC_STORE_RESUME_OPEN_RETRIEVAL, "resume_open"),
        (TC_STORE_SUSPEND_OPEN_RETRIEVAL, "suspend_open"),
        (TC_STORE_ABORT_TIME_RANGE_RETRIEVAL, "abort_range"),
        (TC_STORE_REPORT_STATUS, "report_status"),
        (TC_STORE_CREATE, "create"),
        (TC_STORE_DELETE, "delete"),
        (TC_STORE_REPORT_CONFIGURATION, "report_configuration"),
        (TC_STORE_RESIZE, "resize"),
        (TC_STORE_MAKE_CIRCULAR, "make_circular"),
        (TC_STORE_MAKE_BOUNDED, "make_bounded"),
        (TC_STORE_CHANGE_VIRTUAL_CHANNEL, "change_vc"),
        (TC_STORE_ADD_HK_STRUCTURES, "add_hk"),
        (TC_STORE_DELETE_HK_STRUCTURES, "delete_hk"),
        (TC_STORE_REPORT_HK_STRUCTURES, "report_hk"),
        (TC_STORE_ADD_BLOCKED_EVENTS, "add_blocked"),
        (TC_STORE_DELETE_BLOCKED_EVENTS, "delete_blocked"),
        (TC_STORE_REPORT_BLOCKED_EVENTS, "report_blocked"),
        (TC_STORE_COPY_BY_TIME_WINDOW, "copy_window"),
        (TC_STORE_ADD_DIAG_STRUCTURES, "add_diag"),
        (TC_STORE_DELETE_DIAG_STRUCTURES, "delete_diag"),
        (TC_STORE_REPORT_DIAG_STRUCTURES, "report_diag"),
    )

    def __init__(
        self, initial=(), filestore=None, folder="stores", rate=16, max_stores=8, max_size=None
    ):
        super().__init__()
        self.fs = filestore
        self.folder = folder
        self.rate = rate
        self.max_stores = max_stores
        self.max_size = max_size
        self.stores = {}
        self.controls = {}
        self.initial = list(initial)
        self.stored = 0
        self.retrieved = 0
        self._dirty = False

    def attach(self, app):
        super().attach(app)
        if not self.stores:
            for s in self.initial:
                self._new(s["id"], s["size"], s.get("kind", CIRCULAR), s.get("vc", 0))
                st = self.stores[s["id"]]
                st.enabled = bool(s.get("enabled", False))
                c = self.controls[s["id"]]
                for apid, services in s.get("types", {}).items():
                    c.types.apids[apid] = {k: set(v) for k, v in (services or {}).items()}
                for apid, sids in s.get("hk", {}).items():
                    c.hk.apids[apid] = set(sids)
                st.load()
            if self.initial:
                self.persist()
        app.tm_stores.append(self.offer)

    def _new(self, sid, size, kind, vc):
        st = PacketStore(sid, size, kind, vc, self.fs, self.folder)
        self.stores[sid] = st
        c = self.controls[sid] = Control()
        c.hk.apids[self.app.apid] = set()  # every structure, as for real-time forwarding
        c.diag.apids[self.app.apid] = set()
        return st

    # -------------------------------------------------------------------------- context

    def context(self):
        return [[self.stores[sid].config(), self.controls[sid].context()] for sid in self.stores]

    def restore(self, ctx):
        stores = {}
        controls = {}
        for config, control in ctx:
            st = PacketStore.from_config(config, self.fs, self.folder)
            c = Control()
            c.restore(control)
            stores[st.id] = st
            controls[st.id] = c
        for st in stores.values():
            st.load()
        self.stores, self.controls = stores, controls

    # -------------------------------------------------------------------------- storing

    def offer(self, h, raw, t):
        """The TM pipeline's call for every TM: store it where the configuration says."""
        for sid in self.stores:
            st = self.stores[sid]
            if st.enabled and self.controls[sid].selects(h):
                if st.append(t, raw):
                    self.stored += 1
                else:
                    self.app.count("store_full")

    def store(self, sid):
        st = self.stores.get(sid)
        if st is None:
            raise _failure(FAILURE_UNKNOWN_ID, "no packet store %d" % sid, sid)
        return st

    def _all_or(self, sids):
        if not sids:
            return list(self.stores)
        for sid in sids:
            self.store(sid)
        return sids

    def cyclic(self, now):
        play = self.app.play
        for st in self.stores.values():
            n = 0
            q = st.range_queue
            while q and n < self.rate:
                self._play(play, st, q.pop(0))
                n += 1
            if q is not None and not q:
                st.range_queue = None
            if st.range_queue is None and st.open_active:
                while n < self.rate:
                    raw = st.next_open()
                    if raw is None:
                        break
                    self._play(play, st, raw)
                    n += 1
                    self._dirty = True
        if self._dirty:
            self._dirty = False
            self.persist()

    def _play(self, play, st, raw):
        play(raw, st.vc)
        self.retrieved += 1

    # -------------------------------------------------------------------------- handlers

    def _set_storage(self, req, enabled):
        sids = self._all_or(req.decode(STORES)["stores"])
        req.start()
        for sid in sids:
            self.stores[sid].enabled = enabled
        self.persist()

    def enable(self, req):
        self._set_storage(req, True)

    def disable(self, req):
        self._set_storage(req, False)

    def add_types(self, req):
        tc = req.decode(STORE_TYPES)
        c = self.controls.get(self.store(tc["store"]).id)
        req.start()
        c.types.add(tc["apids"])
        self.persist()

    def delete_types(self, req):
        tc = req.decode(STORE_TYPES)
        c = self.controls.get(self.store(tc["store"]).id)
        if tc["apids"]:
            c.types.check_delete(tc["apids"])
        req.start()
        if tc["apids"]:
            c.types.delete(tc["apids"])
        else:
            c.types.clear()
        self.persist()

    def report_types(self, req):
        sid = self.store(req.decode(ONE_STORE)["store"]).id
        data = STORE_TYPES.pack({"store": sid, "apids": self.controls[sid].types.as_list()})
        req.report(TM_STORE_REPORT_TYPES_REPORT, data)

    def add_hk(self, req):
        tc = req.decode(STORE_HK)
        c = self.controls[self.store(tc["store"]).id]
        req.start()
        for i in tc["apids"]:
            c.hk.add(i["apid"], i["ids"])
        self.persist()

    def delete_hk(self, req):
        tc = req.decode(STORE_HK)
        c = self.controls[self.store(tc["store"]).id]
        for i in tc["apids"]:
            c.hk.check_delete(i["apid"], i["ids"])
        req.start()
        if not tc["apids"]:
            c.hk.apids = {}
        for i in tc["apids"]:
            c.hk.delete(i["apid"], i["ids"])
        self.persist()

    def report_hk(self, req):
        sid = self.store(req.decode(ONE_STORE)["store"]).id
        data = STORE_HK.pack({"store": sid, "apids": self.controls[sid].hk.as_list()})
        req.report(TM_STORE_HK_STRUCTURES_REPORT, data)

    def add_blocked(self, req):
        tc = req.decode(STORE_EVENTS)
        c = self.controls[self.store(tc["store"]).id]
        req.start()
        for i in tc["items"]:
            c.blocked.add(i["apid"], [i["id"]])
        self.persist()

    def delete_blocked(self, req):
        tc = req.decode(STORE_EVENTS)
        c = self.controls[self.store(tc["store"]).id]
        for i in tc["items"]:
            c.blocked.check_delete(i["apid"], [i["id"]])
        req.start()
        if not tc["items"]:
            c.blocked.apids = {}
        for i in tc["items"]:
            c.blocked.delete(i["apid"], [i["id"]])
        self.persist()

    def report_blocked(self, req):
        sid = self.store(req.decode(ONE_STORE)["store"]).id
        data = STORE_EVENTS.pack({"store": sid, "items": self.controls[sid].blocked.pairs()})
        req.report(TM_STORE_BLOCKED_EVENTS_REPORT, data)

    def _start_range(self, req, st, packets):
        if st.range_queue is not None:
            raise _failure(FAILURE_REFUSED, "store %d is being retrieved" % st.id, st.id)
        req.start()
        st.range_queue = packets

    def retrieve_time(self, req):
        tc = req.decode(TIME_RANGE)
        st = self.store(tc["store"])
        start = TIME_TAG.seconds(tc["start"])
        end = TIME_TAG.seconds(tc["end"])
        if end < start:
            raise _failure(FAILURE_REFUSED, "time range ends before it starts", st.id)
        self._start_range(req, st, st.select_time(start, end))

    def retrieve_sequence(self, req):
        tc = req.decode(SEQUENCE_RANGE)
        st = self.store(tc["store"])
        if tc["last"] < tc["first"]:
            raise _failure(FAILURE_REFUSED, "sequence range ends before it starts", st.id)
        self._start_range(req, st, st.select_sequence(tc["first"], tc["last"]))

    def abort_range(self, req):
        sids = self._all_or(req.decode(STORES)["stores"])
        req.start()
        for sid in sids:
            self.stores[sid].range_queue = None

    def delete_content(self, req):
        tc = req.decode(TIME_AND_STORES)
        sids = self._all_or(tc["stores"])
        for sid in sids:
            st = self.stores[sid]
            if st.range_queue is not None or st.open_active:
                raise _failure(FAILURE_REFUSED, "store %d is being retrieved" % sid, sid)
        req.start()
        t = TIME_TAG.seconds(tc["time"])
        for sid in sids:
            self.stores[sid].delete_up_to(t)

    def report_summary(self, req):
        sids = self._all_or(req.decode(STORES)["stores"])
        items = []
        for sid in sids:
            st = self.stores[sid]
            items.append(
                {
                    "store": sid,
                    "oldest": st.oldest(),
                    "newest": st.newest(),
                    "open_start": st.open_start,
                    "fill": st.fill(),
                    "fill_open": st.fill_from_open(),
                    "count": len(st.packets),
                    "first_seq": st.packets[0][0] if st.packets else 0,
                    "last_seq": st.packets[-1][0] if st.packets else 0,
                }
            )
        req.report(TM_STORE_CONTENT_SUMMARY_REPORT, SUMMARY_REPORT.pack({"stores": items}))

    def change_open_start(self, req):
        tc = req.decode(TIME_AND_STORES)
        sids = self._all_or(tc["stores"])
        for sid in sids:
            if self.stores[sid].open_active:
                raise _failure(FAILURE_REFUSED, "open retrieval of %d is running" % sid, sid)
        req.start()
        t = TIME_TAG.seconds(tc["time"])
        for sid in sids:
            st = self.stores[sid]
            st.open_start = t
            st.open_next = 0
        self.persist()

    def _set_open(self, req, active):
        sids = self._all_or(req.decode(STORES)["stores"])
        req.start()
        for sid in sids:
            self.stores[sid].open_active = active
        self.persist()

    def resume_open(self, req):
        self._set_open(req, True)

    def suspend_open(self, req):
        self._set_open(req, False)

    def report_status(self, req):
        req.decode(EMPTY)
        items = []
        for sid in self.stores:
            st = self.stores[sid]
            items.append(
                {
                    "store": sid,
                    "storage": 1 if st.enabled else 0,
                    "open_retrieval": 1 if st.open_active else 0,
                    "range_retrieval": 1 if st.range_queue is not None else 0,
                }
            )
        req.report(TM_STORE_STATUS_REPORT, STATUS_REPORT.pack({"stores": items}))

    def create(self, req):
        items = req.decode(CONFIGURATION)["stores"]
        seen = []
        for i in items:
            sid = i["store"]
            if sid in self.stores or sid in seen:
                raise _failure(FAILURE_REFUSED, "store %d exists" % sid, sid)
            if i["kind"] not in KIND_NAMES:
                raise _failure(FAILURE_REFUSED, "store type %d" % i["kind"], sid)
            if i["size"] == 0 or (self.max_size is not None and i["size"] > self.max_size):
                raise _failure(FAILURE_REFUSED, "store size %d" % i["size"], sid)
            seen.append(sid)
        if len(self.stores) + len(items) > self.max_stores:
            raise PusFailure(FAILURE_REFUSED, "at most %d packet stores" % self.max_stores)
        req.start()
        for i in items:
            self._new(i["store"], i["size"], i["kind"], i["vc"]).create_log()
        self.persist()

    def _idle(self, st):
        if st.enabled or st.open_active or st.range_queue is not None:
            raise _failure(FAILURE_REFUSED, "store %d is in use" % st.id, st.id)

    def delete(self, req):
        sids = self._all_or(req.decode(STORES)["stores"])
        for sid in sids:
            self._idle(self.stores[sid])
        req.start()
        for sid in sids:
            self.stores.pop(sid).remove_log()
            self.controls.pop(sid)
        self.persist()

    def report_configuration(self, req):
        req.decode(EMPTY)
        items = []
        for sid in self.stores:
            st = self.stores[sid]
            items.append({"store": sid, "size": st.size, "kind": st.kind, "vc": st.vc})
        req.report(TM_STORE_CONFIGURATION_REPORT, CONFIGURATION.pack({"stores": items}))

    def resize(self, req):
        items = req.decode(RESIZE)["stores"]
        for i in items:
            st = self.store(i["store"])
            self._idle(st)
            if i["size"] == 0 or (self.max_size is not None and i["size"] > self.max_size):
                raise _failure(FAILURE_REFUSED, "store size %d" % i["size"], st.id)
            if st.kind == BOUNDED and st.used > i["size"]:
                raise _failure(FAILURE_REFUSED, "bounded store holds more", st.id)
        req.start()
        for i in items:
            self.stores[i["store"]].shrink_to(i["size"])
        self.persist()

    def _set_kind(self, req, kind):
        sids = self._all_or(req.decode(STORES)["stores"])
        for sid in sids:
            self._idle(self.stores[sid])
        req.start()
        for sid in sids:
            self.stores[sid].kind = kind
        self.persist()

    def make_circular(self, req):
        self._set_kind(req, CIRCULAR)

    def make_bounded(self, req):
        self._set_kind(req, BOUNDED)

    def change_vc(self, req):
        tc = req.decode(CHANGE_VC)
        st = self.store(tc["store"])
        if st.open_active or st.range_queue is not None:
            raise _failure(FAILURE_REFUSED, "store %d is being retrieved" % st.id, st.id)
        req.start()
        st.vc = tc["vc"]
        self.persist()
