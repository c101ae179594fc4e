"""ST[14] real-time forwarding control: which TM leaves the application process in real time.

Four selections decide (ECSS-E-ST-70-41C 6.14): the report types (APID, service, subtype),
the housekeeping structure IDs per APID for TM[3,25], the diagnostic structure IDs per APID for
TM[3,26], and the event IDs per APID whose TM[5,x] are blocked. The provider is one of the
application process's ``tm_filters``; what it withholds can still be stored by ST[15].
Initially every report of the process's own APID is forwarded. The selections persist in the
context store.
"""

from obsw.pus.messages import (
    SERVICE_REAL_TIME_FORWARDING,
    TC_FWD_ADD_BLOCKED_EVENTS,
    TC_FWD_ADD_DIAG_STRUCTURES,
    TC_FWD_ADD_HK_STRUCTURES,
    TC_FWD_ADD_REPORT_TYPES,
    TC_FWD_DELETE_BLOCKED_EVENTS,
    TC_FWD_DELETE_DIAG_STRUCTURES,
    TC_FWD_DELETE_HK_STRUCTURES,
    TC_FWD_DELETE_REPORT_TYPES,
    TC_FWD_REPORT_BLOCKED_EVENTS,
    TC_FWD_REPORT_DIAG_STRUCTURES,
    TC_FWD_REPORT_HK_STRUCTURES,
    TC_FWD_REPORT_REPORT_TYPES,
    TM_FWD_BLOCKED_EVENTS_REPORT,
    TM_FWD_DIAG_STRUCTURES_REPORT,
    TM_FWD_HK_STRUCTURES_REPORT,
    TM_FWD_REPORT_TYPES_REPORT,
)
from obsw.pus.services.base import Service, ServiceUser
from obsw.pus.services.report_types import (
    EVENT_IDS,
    HK_IDS,
    REPORT_TYPES,
    IdSelection,
    ReportTypes,
    hk_or_event_id,
)
from obsw.pus.structure import Structure

EMPTY = Structure([])
_DIAG_REPORT = (3, 26)


def types_list(selection):
    """``{apid: {service: [subtypes]}}`` (or ``{apid: None}`` for all) as TC items."""
    out = []
    for apid in selection:
        services = selection[apid] or {}
        out.append(
            {
                "apid": apid,
                "services": [
                    {"service": s, "subtypes": list(services[s] or ())} for s in services
                ],
            }
        )
    return out


def ids_list(selection):
    """``{apid: [ids]}`` (an empty list for all IDs) as TC items."""
    return [{"apid": a, "ids": list(selection[a] or ())} for a in selection]


def pairs_list(selection):
    """``{apid: [event ids]}`` as (APID, event ID) pairs."""
    out = []
    for a in selection:
        for i in selection[a]:
            out.append({"apid": a, "id": i})
    return out


class ForwardingControl(Service):
    """The service 14 provider; ``forwards(header)`` is asked for every TM."""

    SERVICE = SERVICE_REAL_TIME_FORWARDING
    REPORTS = (
        TM_FWD_REPORT_TYPES_REPORT,
        TM_FWD_HK_STRUCTURES_REPORT,
        TM_FWD_DIAG_STRUCTURES_REPORT,
        TM_FWD_BLOCKED_EVENTS_REPORT,
    )
    NAME = "s14"
    HANDLERS = (
        (TC_FWD_ADD_REPORT_TYPES, "add_types"),
        (TC_FWD_DELETE_REPORT_TYPES, "delete_types"),
        (TC_FWD_REPORT_REPORT_TYPES, "report_types"),
        (TC_FWD_ADD_HK_STRUCTURES, "add_hk"),
        (TC_FWD_DELETE_HK_STRUCTURES, "delete_hk"),
        (TC_FWD_REPORT_HK_STRUCTURES, "report_hk"),
        (TC_FWD_ADD_DIAG_STRUCTURES, "add_diag"),
        (TC_FWD_DELETE_DIAG_STRUCTURES, "delete_diag"),
        (TC_FWD_REPORT_DIAG_STRUCTURES, "report_diag"),
        (TC_FWD_ADD_BLOCKED_EVENTS, "add_blocked"),
        (TC_FWD_DELETE_BLOCKED_EVENTS, "delete_blocked"),
        (TC_FWD_REPORT_BLOCKED_EVENTS, "report_blocked"),
    )

    def __init__(self):
        super().__init__()
        self.types = ReportTypes()
        self.hk = IdSelection()
        self.diag = IdSelection()
        self.blocked = IdSelection()
        self.withheld = 0

    def attach(self, app):
        self.types.apids[app.apid] = {}
        self.hk.apids[app.apid] = set()
        self.diag.apids[app.apid] = set()
        super().attach(app)
        app.tm_filters.append(self.forwards)

    # -------------------------------------------------------------------------- decision

    def forwards(self, h):
        if not self.types.selects(h.apid, h.service, h.subtype):
            self.withheld += 1
            return False
        if h.service == _DIAG_REPORT[0] and h.subtype == _DIAG_REPORT[1]:
            if not self.diag.has(h.apid, h.sid()):
                self.withheld += 1
                return False
            return True
        kind = hk_or_event_id(h)
        if kind is not None:
            if kind[0] == "hk":
                ok = self.hk.has(h.apid, kind[1])
            else:
                ok = not self.blocked.listed(h.apid, kind[1])
            if not ok:
                self.withheld += 1
                return False
        return True

    # -------------------------------------------------------------------------- context

    def context(self):
        ctx = [self.types.context(), self.hk.context(), self.blocked.context()]
        return ctx + [self.diag.context()]

    def restore(self, ctx):
        types, hk, blocked = ctx[:3]
        t = ReportTypes()
        t.restore(types)
        h = IdSelection()
        h.restore(hk)
        b = IdSelection()
        b.restore(blocked)
        d = self.diag
        if len(ctx) > 3:  # contexts saved before diagnostic forwarding keep the initial one
            d = IdSelection()
            d.restore(ctx[3])
        self.types, self.hk, self.blocked, self.diag = t, h, b, d

    # -------------------------------------------------------------------------- handlers

    def add_types(self, req):
        apids = req.decode(REPORT_TYPES)["apids"]
        req.start()
        self.types.add(apids)
        self.persist()

    def delete_types(self, req):
        apids = req.decode(REPORT_TYPES)["apids"]
        if not apids:
            req.start()
            self.types.clear()
        else:
            self.types.check_delete(apids)
            req.start()
            self.types.delete(apids)
        self.persist()

    def report_types(self, req):
        req.decode(EMPTY)
        req.report(TM_FWD_REPORT_TYPES_REPORT, REPORT_TYPES.pack({"apids": self.types.as_list()}))

    def _add_ids(self, req, selection):
        items = req.decode(HK_IDS)["apids"]
        req.start()
        for i in items:
            selection.add(i["apid"], i["ids"])
        self.persist()

    def _delete_ids(self, req, selection):
        items = req.decode(HK_IDS)["apids"]
        if not items:
            req.start()
            selection.apids = {}
        else:
            for i in items:
                selection.check_delete(i["apid"], i["ids"])
            req.start()
            for i in items:
                selection.delete(i["apid"], i["ids"])
        self.persist()

    def add_hk(self, req):
        self._add_ids(req, self.hk)

    def delete_hk(self, req):
        self._delete_ids(req, self.hk)

    def report_hk(self, req):
        req.decode(EMPTY)
        req.report(TM_FWD_HK_STRUCTURES_REPORT, HK_IDS.pack({"apids": self.hk.as_list()}))

    def add_diag(self, req):
        self._add_ids(req, self.diag)

    def delete_diag(self, req):
        self._delete_ids(req, self.diag)

    def report_diag(self, req):
        req.decode(EMPTY)
        req.report(TM_FWD_DIAG_STRUCTURES_REPORT, HK_IDS.pack({"apids": self.diag.as_list()}))

    def add_blocked(self, req):
        items = req.decode(EVENT_IDS)["items"]
        req.start()
        for i in items:
            self.blocked.add(i["apid"], [i["id"]])
        self.persist()

    def delete_blocked(self, req):
        items = req.decode(EVENT_IDS)["items"]
        if not items:
            req.start()
            self.blocked.apids = {}
        else:
            for i in items:
                self.blocked.check_delete(i["apid"], [i["id"]])
            req.start()
            for i in items:
                self.blocked.delete(i["apid"], [i["id"]])
        self.persist()

    def report_blocked(self, req):
        req.decode(EMPTY)
        req.report(TM_FWD_BLOCKED_EVENTS_REPORT, EVENT_IDS.pack({"items": self.blocked.pairs()}))


class ForwardingUser(ServiceUser):
    """The service 14 user. Selections are dicts: ``{apid: {service: [subtypes]}}``."""

    SERVICE = SERVICE_REAL_TIME_FORWARDING
    DECODERS = (
        (TM_FWD_REPORT_TYPES_REPORT, "decode_types"),
        (TM_FWD_HK_STRUCTURES_REPORT, "decode_hk"),
        (TM_FWD_DIAG_STRUCTURES_REPORT, "decode_diag"),
        (TM_FWD_BLOCKED_EVENTS_REPORT, "decode_blocked"),
    )

    def add_types(self, apid, selection):
        data = REPORT_TYPES.pack({"apids": types_list(selection)})
        return self.request(apid, TC_FWD_ADD_REPORT_TYPES, data)

    def delete_types(self, apid, selection):
        """Delete ``selection`` ({} deletes every report type)."""
        data = REPORT_TYPES.pack({"apids": types_list(selection)})
        return self.request(apid, TC_FWD_DELETE_REPORT_TYPES, data)

    def report_types(self, apid):
        return self.request(apid, TC_FWD_REPORT_REPORT_TYPES, b"", TM_FWD_REPORT_TYPES_REPORT)

    def add_hk(self, apid, selection):
        """``selection`` is ``{apid: [SIDs]}`` (an empty list: every SID)."""
        data = HK_IDS.pack({"apids": ids_list(selection)})
        return self.request(apid, TC_FWD_ADD_HK_STRUCTURES, data)

    def delete_hk(self, apid, selection):
        data = HK_IDS.pack({"apids": ids_list(selection)})
        return self.request(apid, TC_FWD_DELETE_HK_STRUCTURES, data)

    def report_hk(self, apid):
        return self.request(apid, TC_FWD_REPORT_HK_STRUCTURES, b"", TM_FWD_HK_STRUCTURES_REPORT)

    def add_diag(self, apid, selection):
        """``selection`` is ``{apid: [diagnostic SIDs]}`` (an empty list: every SID)."""
        data = HK_IDS.pack({"apids": ids_list(selection)})
        return self.request(apid, TC_FWD_ADD_DIAG_STRUCTURES, data)

    def delete_diag(self, apid, selection):
        data = HK_IDS.pack({"apids": ids_list(selection)})
        return self.request(apid, TC_FWD_DELETE_DIAG_STRUCTURES, data)

    def report_diag(self, apid):
        return self.request(
            apid, TC_FWD_REPORT_DIAG_STRUCTURES, b"", TM_FWD_DIAG_STRUCTURES_REPORT
        )

    def add_blocked(self, apid, selection):
        """``selection`` is ``{apid: [event IDs]}``."""
        data = EVENT_IDS.pack({"items": pairs_list(selection)})
        return self.request(apid, TC_FWD_ADD_BLOCKED_EVENTS, data)

    def delete_blocked(self, apid, selection):
        data = EVENT_IDS.pack({"items": pairs_list(selection)})
        return self.request(apid, TC_FWD_DELETE_BLOCKED_EVENTS, data)

    def report_blocked(self, apid):
        return self.request(apid, TC_FWD_REPORT_BLOCKED_EVENTS, b"", TM_FWD_BLOCKED_EVENTS_REPORT)

    def decode_types(self, tm):
        return {"types": types_dict(REPORT_TYPES.unpack(tm.data)["apids"])}

    def decode_hk(self, tm):
        return {"hk": {i["apid"]: i["ids"] for i in HK_IDS.unpack(tm.data)["apids"]}}

    def decode_diag(self, tm):
        return {"diag": {i["apid"]: i["ids"] for i in HK_IDS.unpack(tm.data)["apids"]}}

    def decode_blocked(self, tm):
        out = {}
        for i in EVENT_IDS.unpack(tm.data)["items"]:
            out.setdefault(i["apid"], []).append(i["id"])
        return {"blocked": out}


def types_dict(apids):
    """TC/TM items back to ``{apid: {service: [subtypes]}}`` ({} for all)."""
    out = {}
    for a in apids:
        out[a["apid"]] = {s["service"]: s["subtypes"] for s in a["services"]}
    return out
