"""ST[15] service user: storage and retrieval requests and the decoding of their reports."""

from obsw.pus.messages import (
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
    TM_STORE_BLOCKED_EVENTS_REPORT,
    TM_STORE_CONFIGURATION_REPORT,
    TM_STORE_CONTENT_SUMMARY_REPORT,
    TM_STORE_DIAG_STRUCTURES_REPORT,
    TM_STORE_HK_STRUCTURES_REPORT,
    TM_STORE_REPORT_TYPES_REPORT,
    TM_STORE_STATUS_REPORT,
)
from obsw.pus.services.base import ServiceUser
from obsw.pus.services.s14_forwarding import ids_list, pairs_list, types_dict, types_list
from obsw.pus.services.s15_layouts import (
    CHANGE_VC,
    CONFIGURATION,
    COPY_WINDOW,
    ONE_STORE,
    RESIZE,
    SEQUENCE_RANGE,
    STATUS_REPORT,
    STORE_DIAG,
    STORE_EVENTS,
    STORE_HK,
    STORE_TYPES,
    STORES,
    SUMMARY_REPORT,
    TIME_AND_STORES,
    TIME_RANGE,
    TIME_TAG,
    WINDOW_AFTER,
    WINDOW_BEFORE,
    WINDOW_FROM_TO,
)


def _seconds(items, *keys):
    for i in items:
        for k in keys:
            i[k] = TIME_TAG.seconds(i[k])
    return items


class StorageUser(ServiceUser):
    """The service 15 user. Times are seconds of the TM time code's epoch."""

    SERVICE = SERVICE_STORAGE_AND_RETRIEVAL
    DECODERS = (
        (TM_STORE_REPORT_TYPES_REPORT, "decode_types"),
        (TM_STORE_CONTENT_SUMMARY_REPORT, "decode_summary"),
        (TM_STORE_STATUS_REPORT, "decode_status"),
        (TM_STORE_CONFIGURATION_REPORT, "decode_configuration"),
        (TM_STORE_HK_STRUCTURES_REPORT, "decode_hk"),
        (TM_STORE_BLOCKED_EVENTS_REPORT, "decode_blocked"),
        (TM_STORE_DIAG_STRUCTURES_REPORT, "decode_diag"),
    )

    def _stores(self, apid, message_type, stores, expect=None):
        return self.request(apid, message_type, STORES.pack({"stores": list(stores)}), expect)

    def enable(self, apid, stores=()):
        """Enable the storage function of ``stores`` (none named: every store)."""
        return self._stores(apid, TC_STORE_ENABLE_STORAGE, stores)

    def disable(self, apid, stores=()):
        return self._stores(apid, TC_STORE_DISABLE_STORAGE, stores)

    def add_types(self, apid, store, selection):
        """``selection`` is ``{apid: {service: [subtypes]}}`` ({} or [] for all)."""
        data = STORE_TYPES.pack({"store": store, "apids": types_list(selection)})
        return self.request(apid, TC_STORE_ADD_REPORT_TYPES, data)

    def delete_types(self, apid, store, selection):
        data = STORE_TYPES.pack({"store": store, "apids": types_list(selection)})
        return self.request(apid, TC_STORE_DELETE_REPORT_TYPES, data)

    def report_types(self, apid, store):
        data = ONE_STORE.pack({"store": store})
        return self.request(apid, TC_STORE_REPORT_REPORT_TYPES, data, TM_STORE_REPORT_TYPES_REPORT)

    def add_hk(self, apid, store, selection):
        data = STORE_HK.pack({"store": store, "apids": ids_list(selection)})
        return self.request(apid, TC_STORE_ADD_HK_STRUCTURES, data)

    def delete_hk(self, apid, store, selection):
        data = STORE_HK.pack({"store": store, "apids": ids_list(selection)})
        return self.request(apid, TC_STORE_DELETE_HK_STRUCTURES, data)

    def report_hk(self, apid, store):
        data = ONE_STORE.pack({"store": store})
        return self.request(
            apid, TC_STORE_REPORT_HK_STRUCTURES, data, TM_STORE_HK_STRUCTURES_REPORT
        )

    def add_blocked(self, apid, store, selection):
        data = STORE_EVENTS.pack({"store": store, "items": pairs_list(selection)})
        return self.request(apid, TC_STORE_ADD_BLOCKED_EVENTS, data)

    def delete_blocked(self, apid, store, selection):
        data = STORE_EVENTS.pack({"store": store, "items": pairs_list(selection)})
        return self.request(apid, TC_STORE_DELETE_BLOCKED_EVENTS, data)

    def report_blocked(self, apid, store):
        data = ONE_STORE.pack({"store": store})
        return self.request(
            apid, TC_STORE_REPORT_BLOCKED_EVENTS, data, TM_STORE_BLOCKED_EVENTS_REPORT
        )

    def retrieve_time(self, apid, store, start, end):
        """Downlink the packets stored between ``start`` and ``end`` (seconds)."""
        data = TIME_RANGE.pack({"store": store, "start": start, "end": end})
        return self.request(apid, TC_STORE_START_TIME_RANGE_RETRIEVAL, data)

    def retrieve_sequence(self, apid, store, first, last):
        """Downlink the packets with storage sequence numbers ``first`` .. ``last``."""
        data = SEQUENCE_RANGE.pack({"store": store, "first": first, "last": last})
        return self.request(apid, TC_STORE_RETRIEVE_SEQUENCE_RANGE, data)

    def abort_retrieval(self, apid, stores=()):
        return self._stores(apid, TC_STORE_ABORT_TIME_RANGE_RETRIEVAL, stores)

    def delete_content(self, apid, time, stores=()):
        data = TIME_AND_STORES.pack({"time": time, "stores": list(stores)})
        return self.request(apid, TC_STORE_DELETE_CONTENT_UP_TO, data)

    def report_summary(self, apid, stores=()):
        return self._stores(
            apid, TC_STORE_REPORT_CONTENT_SUMMARY, stores, TM_STORE_CONTENT_SUMMARY_REPORT
        )

    def change_open_start(self, apid, time, stores=()):
        data = TIME_AND_STORES.pack({"time": time, "stores": list(stores)})
        return self.request(apid, TC_STORE_CHANGE_OPEN_RETRIEVAL_START, data)

    def resume_open(self, apid, stores=()):
        return self._stores(apid, TC_STORE_RESUME_OPEN_RETRIEVAL, stores)

    def suspend_open(self, apid, stores=()):
        return self._stores(apid, TC_STORE_SUSPEND_OPEN_RETRIEVAL, stores)

    def report_status(self, apid):
        return self.request(apid, TC_STORE_REPORT_STATUS, b"", TM_STORE_STATUS_REPORT)

    def create(self, apid, stores):
        """``stores``: dicts with ``store``, ``size`` (octets), ``kind`` (0 circular,
        1 bounded) and ``vc``."""
        return self.request(apid, TC_STORE_CREATE, CONFIGURATION.pack({"stores": list(stores)}))

    def delete(self, apid, stores=()):
        return self._stores(apid, TC_STORE_DELETE, stores)

    def report_configuration(self, apid):
        return self.request(
            apid, TC_STORE_REPORT_CONFIGURATION, b"", TM_STORE_CONFIGURATION_REPORT
        )

    def resize(self, apid, sizes):
        """``sizes`` maps store ID -> new size in octets."""
        items = [{"store": s, "size": n} for s, n in sizes.items()]
        return self.request(apid, TC_STORE_RESIZE, RESIZE.pack({"stores": items}))

    def make_circular(self, apid, stores):
        return self._stores(apid, TC_STORE_MAKE_CIRCULAR, stores)

    def make_bounded(self, apid, stores):
        return self._stores(apid, TC_STORE_MAKE_BOUNDED, stores)

    def change_vc(self, apid, store, vc):
        data = CHANGE_VC.pack({"store": store, "vc": vc})
        return self.request(apid, TC_STORE_CHANGE_VIRTUAL_CHANNEL, data)

    def decode_types(self, tm):
        out = STORE_TYPES.unpack(tm.data)
        return {"store": out["store"], "types": types_dict(out["apids"])}

    def decode_summary(self, tm):
        items = SUMMARY_REPORT.unpack(tm.data)["stores"]
        return {"stores": _seconds(items, "oldest", "newest", "open_start")}

    def decode_status(self, tm):
        items = STATUS_REPORT.unpack(tm.data)["stores"]
        for i in items:
            for k in ("storage", "open_retrieval", "range_retrieval"):
                i[k] = bool(i[k])
        return {"stores": items}

    def decode_configuration(self, tm):
        return CONFIGURATION.unpack(tm.data)

    def decode_hk(self, tm):
        out = STORE_HK.unpack(tm.data)
        return {"store": out["store"], "hk": {i["apid"]: i["ids"] for i in out["apids"]}}

    def decode_blocked(self, tm):
        out = STORE_EVENTS.unpack(tm.data)
        blocked = {}
        for i in out["items"]:
            blocked.setdefault(i["apid"], []).append(i["id"])
        return {"store": out["store"], "blocked": blocked}

    # ---------------------------------------------------------------- TC[15,24], diagnostics

    def copy_window(self, apid, source, target, start=None, end=None):
        """TC[15,24]: copy the packets of ``source`` stored from ``start`` to ``end``
        (seconds; one of them None for "after" or "before") into the empty ``target``."""
        if start is None and end is None:
            raise ValueError("a time window needs a start, an end or both")
        if end is None:
            window = WINDOW_AFTER
        elif start is None:
            window = WINDOW_BEFORE
        else:
            window = WINDOW_FROM_TO
        values = {
            "window": window,
            "tag1": start or 0,
            "tag2": end or 0,
            "source": source,
            "target": target,
        }
        return self.request(apid, TC_STORE_COPY_BY_TIME_WINDOW, COPY_WINDOW.pack(values))

    def add_diag(self, apid, store, selection):
        """TC[15,31]; ``selection`` is ``{apid: [structure IDs]}`` ([] for all)."""
        data = STORE_DIAG.pack({"store": store, "apids": ids_list(selection)})
        return self.request(apid, TC_STORE_ADD_DIAG_STRUCTURES, data)

    def delete_diag(self, apid, store, selection):
        """TC[15,32]."""
        data = STORE_DIAG.pack({"store": store, "apids": ids_list(selection)})
        return self.request(apid, TC_STORE_DELETE_DIAG_STRUCTURES, data)

    def report_diag(self, apid, store):
        """TC[15,37]; the reply is TM[15,38]."""
        data = ONE_STORE.pack({"store": store})
        return self.request(
            apid, TC_STORE_REPORT_DIAG_STRUCTURES, data, TM_STORE_DIAG_STRUCTURES_REPORT
        )

    def decode_diag(self, tm):
        out = STORE_DIAG.unpack(tm.data)
        return {"store": out["store"], "diag": {i["apid"]: i["ids"] for i in out["apids"]}}
