"""The user side shared by ST[11] and ST[22]: scheduling requests built, reports decoded.

``embed`` builds a TC for on-board use (to be scheduled, sequenced or run as an action) with
the user process's own sequence count and source ID and opens its transaction, so the
TC's verification reports find it whenever it runs on board.
"""

from obsw.pus.packets import ACK_ALL, PusError
from obsw.pus.services.base import ServiceUser
from obsw.pus.services.schedule_layouts import (
    GROUPS,
    STATUS_REPORT,
    SUBSCHEDULES,
    WINDOW_ALL,
    WINDOW_FROM,
    WINDOW_FROM_TO,
    WINDOW_TO,
    Layouts,
)
from obsw.pus.tc import PusTc
from obsw.pus.user import Transaction


def embed(proc, apid, service, subtype, data=b"", ack=ACK_ALL, expect=None):
    """A TC for on-board use (scheduled, sequenced, or an action) from the user process
    ``proc``: its own sequence count and source ID. Returns ``(raw, transaction)``; the
    transaction is open in ``proc``, so the reports of the TC, whenever it runs, find it."""
    tc = PusTc(
        apid,
        service,
        subtype,
        data,
        proc.sequence.next(apid),
        ack,
        proc.source_id,
        config=proc.config,
    )
    tx = Transaction(tc, expect, proc.clock.now())
    proc.open.append(tx)
    if len(proc.open) > proc.keep:
        proc.open.pop(0)
        proc.count("given_up")
    return tc.pack(), tx


def request_bytes(request):
    """TC bytes from bytes, a PusTc, or a Transaction (of ``embed``)."""
    if isinstance(request, Transaction):
        return request.tc.pack()
    if isinstance(request, PusTc):
        return request.pack()
    return bytes(request)


def describe_request(raw, config=None):
    """What a scheduled request is: its type and request ID, as a dict."""
    try:
        tc = PusTc.unpack(raw) if config is None else PusTc.unpack(raw, config)
    except PusError:
        return {"request": bytes(raw)}
    return {
        "type": (tc.service, tc.subtype),
        "source": tc.source_id,
        "apid": tc.apid,
        "seq_count": tc.seq_count,
        "request": bytes(raw),
    }


class ScheduleUser(ServiceUser):
    """The user core of services 11 and 22: requests by role, reports decoded.

    A tag is given and reported as ``TAG_NAME`` (seconds of on-board time, or a position);
    activities are named by request IDs ``(source, apid, seq_count)`` or by the transaction
    ``embed`` gave.
    """

    TAG = None
    OFFSET = None
    TAG_NAME = "tag"
    TC = {}  # role -> TC message type
    TM_DETAIL = TM_SUMMARY = TM_SUBSCHEDULES = TM_GROUPS = None

    def __init__(self):
        super().__init__()
        self.layouts = Layouts(self.TAG, self.OFFSET)

    def tag_out(self, value):
        return value

    def embed(self, apid, service, subtype, data=b"", ack=ACK_ALL, expect=None):
        """A TC to schedule; see ``embed``."""
        return embed(self.proc, apid, service, subtype, data, ack, expect)

    def _ids(self, ids):
        out = []
        for r in ids:
            if isinstance(r, Transaction):
                r = (r.tc.source_id, r.tc.apid, r.tc.seq_count)
            out.append({"source": r[0], "apid": r[1], "seq_count": r[2]})
        return {"ids": out}

    def _filter(self, window, start, end, subschedules, groups):
        values = {
            "window": window,
            "subschedules": list(subschedules),
            "groups": list(groups),
        }
        if window in (WINDOW_FROM_TO, WINDOW_FROM):
            values["from"] = start
        if window in (WINDOW_FROM_TO, WINDOW_TO):
            values["to"] = end
        return values

    def _window(self, start, end):
        if start is None:
            return WINDOW_ALL if end is None else WINDOW_TO
        return WINDOW_FROM if end is None else WINDOW_FROM_TO

    def enable(self, apid):
        return self.request(apid, self.TC["enable"])

    def disable(self, apid):
        return self.request(apid, self.TC["disable"])

    def reset(self, apid):
        return self.request(apid, self.TC["reset"])

    def insert(self, apid, activities):
        """``activities``: (tag, request) or (tag, request, subschedule, group) each; a
        request is TC bytes, a PusTc or the transaction of ``embed``."""
        items = []
        for a in activities:
            sub = a[2] if len(a) > 2 else 0
            group = a[3] if len(a) > 3 else 0
            items.append(
                {"subschedule": sub, "group": group, "tag": a[0], "request": request_bytes(a[1])}
            )
        return self.request(
            apid, self.TC["insert"], self.layouts.activities.pack({"items": items})
        )

    def delete(self, apid, ids):
        return self.request(apid, self.TC["delete_ids"], self.layouts.ids.pack(self._ids(ids)))

    def _filtered(self, role, apid, start, end, subschedules, groups, expect=None, offset=None):
        w = self._window(start, end)
        values = self._filter(w, start, end, subschedules, groups)
        if offset is None:
            data = self.layouts.filters[w].pack(values)
        else:
            values["offset"] = offset
            data = self.layouts.shift_filters[w].pack(values)
        return self.request(apid, self.TC[role], data, expect)

    def delete_filter(self, apid, start=None, end=None, subschedules=(), groups=()):
        """Delete the activities with tags in [start, end] (None: open) of the given
        sub-schedules and groups (empty: any)."""
        return self._filtered("delete_filter", apid, start, end, subschedules, groups)

    def shift(self, apid, offset, ids):
        data = self.layouts.shift_ids.pack({"offset": offset, "ids": self._ids(ids)["ids"]})
        return self.request(apid, self.TC["shift_ids"], data)

    def shift_filter(self, apid, offset, start=None, end=None, subschedules=(), groups=()):
        return self._filtered(
            "shift_filter", apid, start, end, subschedules, groups, offset=offset
        )

    def shift_all(self, apid, offset):
        data = self.layouts.shift_all.pack({"offset": offset})
        return self.request(apid, self.TC["shift_all"], data)

    def detail(self, apid, ids):
        data = self.layouts.ids.pack(self._ids(ids))
        return self.request(apid, self.TC["detail_ids"], data, self.TM_DETAIL)

    def detail_filter(self, apid, start=None, end=None, subschedules=(), groups=()):
        return self._filtered(
            "detail_filter", apid, start, end, subschedules, groups, self.TM_DETAIL
        )

    def detail_all(self, apid):
        return self.request(apid, self.TC["detail_all"], b"", self.TM_DETAIL)

    def summary(self, apid, ids):
        data = self.layouts.ids.pack(self._ids(ids))
        return self.request(apid, self.TC["summary_ids"], data, self.TM_SUMMARY)

    def summary_filter(self, apid, start=None, end=None, subschedules=(), groups=()):
        return self._filtered(
            "summary_filter", apid, start, end, subschedules, groups, self.TM_SUMMARY
        )

    def summary_all(self, apid):
        return self.request(apid, self.TC["summary_all"], b"", self.TM_SUMMARY)

    def subschedule_status(self, apid):
        return self.request(apid, self.TC["report_subschedules"], b"", self.TM_SUBSCHEDULES)

    def _ids_request(self, role, apid, ids, layout):
        return self.request(apid, self.TC[role], layout.pack({"ids": list(ids)}))

    def enable_subschedules(self, apid, ids):
        return self._ids_request("enable_subschedules", apid, ids, SUBSCHEDULES)

    def disable_subschedules(self, apid, ids):
        return self._ids_request("disable_subschedules", apid, ids, SUBSCHEDULES)

    def create_groups(self, apid, ids):
        return self._ids_request("create_groups", apid, ids, GROUPS)

    def delete_groups(self, apid, ids):
        return self._ids_request("delete_groups", apid, ids, GROUPS)

    def enable_groups(self, apid, ids):
        return self._ids_request("enable_groups", apid, ids, GROUPS)

    def disable_groups(self, apid, ids):
        return self._ids_request("disable_groups", apid, ids, GROUPS)

    def group_status(self, apid):
        return self.request(apid, self.TC["report_groups"], b"", self.TM_GROUPS)

    # -------------------------------------------------------------------------- decoders

    def decode_detail(self, tm):
        out = []
        for i in self.layouts.activities.unpack(tm.data)["items"]:
            d = describe_request(i["request"], self.proc.config if self.proc else None)
            d["subschedule"] = i["subschedule"]
            d["group"] = i["group"]
            d[self.TAG_NAME] = self.tag_out(i["tag"])
            out.append(d)
        return {"activities": out}

    def decode_summary(self, tm):
        out = []
        for i in self.layouts.summary.unpack(tm.data)["items"]:
            i[self.TAG_NAME] = self.tag_out(i.pop("tag"))
            out.append(i)
        return {"activities": out}

    def decode_status(self, tm):
        items = STATUS_REPORT.unpack(tm.data)["items"]
        return {"items": [{"id": i["id"], "enabled": bool(i["enabled"])} for i in items]}
