"""ST[03] housekeeping: the service user (ground side), for both structure sets and
parameter functional reporting."""

from obsw.pus.messages import (
    SERVICE_HOUSEKEEPING,
    TC_HK_ADD_TO_FUNCTIONAL_REPORTING,
    TC_HK_APPEND_DIAG_PARAMETERS,
    TC_HK_APPEND_HK_PARAMETERS,
    TC_HK_APPLY_FUNCTIONAL_REPORTING,
    TC_HK_CREATE_DIAG_STRUCTURE,
    TC_HK_CREATE_FUNCTIONAL_REPORTING,
    TC_HK_CREATE_HK_STRUCTURE,
    TC_HK_DELETE_DIAG_STRUCTURES,
    TC_HK_DELETE_FUNCTIONAL_REPORTING,
    TC_HK_DELETE_HK_STRUCTURES,
    TC_HK_DISABLE_DIAG_REPORTS,
    TC_HK_DISABLE_HK_REPORTS,
    TC_HK_ENABLE_DIAG_REPORTS,
    TC_HK_ENABLE_HK_REPORTS,
    TC_HK_MODIFY_DIAG_INTERVAL,
    TC_HK_MODIFY_FUNCTIONAL_REPORTING_PERIODS,
    TC_HK_MODIFY_HK_INTERVAL,
    TC_HK_ONE_SHOT_DIAG,
    TC_HK_ONE_SHOT_HK,
    TC_HK_REMOVE_FROM_FUNCTIONAL_REPORTING,
    TC_HK_REPORT_DIAG_PERIODIC_PROPERTIES,
    TC_HK_REPORT_DIAG_STRUCTURES,
    TC_HK_REPORT_FUNCTIONAL_REPORTING,
    TC_HK_REPORT_HK_PERIODIC_PROPERTIES,
    TC_HK_REPORT_HK_STRUCTURES,
    TM_HK_DIAG_PERIODIC_PROPERTIES_REPORT,
    TM_HK_DIAG_REPORT,
    TM_HK_DIAG_STRUCTURE_REPORT,
    TM_HK_FUNCTIONAL_REPORTING_REPORT,
    TM_HK_HK_PERIODIC_PROPERTIES_REPORT,
    TM_HK_HK_REPORT,
    TM_HK_HK_STRUCTURE_REPORT,
)
from obsw.pus.services.base import STRUCTURE_ID, ServiceUser
from obsw.pus.services.s03_layouts import (
    APPEND,
    CREATE,
    FUNCTIONAL,
    FUNCTIONAL_IDS,
    FUNCTIONAL_REMOVE,
    FUNCTIONAL_REPORT,
    INTERVALS,
    PROPERTIES_REPORT,
    SID_ONLY,
    SIDS,
    STRUCTURE_REPORT,
)
from obsw.pus.structure import Structure

# per set: create, delete, enable, disable, report structures, one-shot, append, interval,
# report properties (TCs) and the parameter report, structure report, properties report (TM)
_TC = {
    "hk": (TC_HK_CREATE_HK_STRUCTURE, TC_HK_DELETE_HK_STRUCTURES, TC_HK_ENABLE_HK_REPORTS,
           TC_HK_DISABLE_HK_REPORTS, TC_HK_REPORT_HK_STRUCTURES, TC_HK_ONE_SHOT_HK,
           TC_HK_APPEND_HK_PARAMETERS, TC_HK_MODIFY_HK_INTERVAL,
           TC_HK_REPORT_HK_PERIODIC_PROPERTIES),
    "diag": (TC_HK_CREATE_DIAG_STRUCTURE, TC_HK_DELETE_DIAG_STRUCTURES, TC_HK_ENABLE_DIAG_REPORTS,
             TC_HK_DISABLE_DIAG_REPORTS, TC_HK_REPORT_DIAG_STRUCTURES, TC_HK_ONE_SHOT_DIAG,
             TC_HK_APPEND_DIAG_PARAMETERS, TC_HK_MODIFY_DIAG_INTERVAL,
             TC_HK_REPORT_DIAG_PERIODIC_PROPERTIES),
}  # fmt: skip
_TM = {
    "hk": (TM_HK_HK_REPORT, TM_HK_HK_STRUCTURE_REPORT, TM_HK_HK_PERIODIC_PROPERTIES_REPORT),
    "diag": (
        TM_HK_DIAG_REPORT,
        TM_HK_DIAG_STRUCTURE_REPORT,
        TM_HK_DIAG_PERIODIC_PROPERTIES_REPORT,
    ),
}
KINDS = ("hk", "diag")
_DIAG_SUBTYPES = tuple(t[1] for t in _TM["diag"])


def _sids(sids):
    return SIDS.pack({"sids": list(sids)})


def _definitions(entries):
    """{sid: (enabled, interval)} -> TC items, in SID order."""
    return [
        {"sid": s, "enabled": 1 if entries[s][0] else 0, "interval": entries[s][1]}
        for s in sorted(entries)
    ]


class HousekeepingUser(ServiceUser):
    """The service 3 user; ``types(pid)`` gives a parameter's field type, ``names(pid)`` its
    name (both from the spacecraft database). Structures are learnt from the requests sent,
    the structure reports received, and ``known`` (housekeeping) and ``diagnostic``. Methods
    taking ``kind`` serve both sets: "hk" (default) or "diag"."""

    SERVICE = SERVICE_HOUSEKEEPING
    DECODERS = (
        (TM_HK_HK_STRUCTURE_REPORT, "decode_structure"),
        (TM_HK_DIAG_STRUCTURE_REPORT, "decode_structure"),
        (TM_HK_HK_REPORT, "decode_report"),
        (TM_HK_DIAG_REPORT, "decode_report"),
        (TM_HK_HK_PERIODIC_PROPERTIES_REPORT, "decode_properties"),
        (TM_HK_DIAG_PERIODIC_PROPERTIES_REPORT, "decode_properties"),
        (TM_HK_FUNCTIONAL_REPORTING_REPORT, "decode_functional"),
    )

    def __init__(self, types, names=None, known=(), diagnostic=()):
        super().__init__()
        self.types = types
        self.names = names
        self.structures = {}  # sid -> [pid] (housekeeping)
        self.diagnostics = {}  # sid -> [pid]
        self._sets = {"hk": self.structures, "diag": self.diagnostics}
        self._layouts = {}  # (kind, sid) -> Structure
        for kind, listed in (("hk", known), ("diag", diagnostic)):
            for s in listed:
                self.learn(s["sid"], s["parameters"], kind)

    def learn(self, sid, parameters, kind="hk"):
        self._sets[kind][sid] = list(parameters)
        self._layouts.pop((kind, sid), None)

    # -------------------------------------------------------------------------- requests

    def create(self, apid, sid, interval, parameters, kind="hk"):
        self.learn(sid, parameters, kind)
        data = CREATE.pack(
            {"sid": sid, "interval": interval, "parameters": list(parameters), "groups": []}
        )
        return self.request(apid, _TC[kind][0], data)

    def delete(self, apid, sids, kind="hk"):
        return self.request(apid, _TC[kind][1], _sids(sids))

    def enable(self, apid, sids, kind="hk"):
        return self.request(apid, _TC[kind][2], _sids(sids))

    def disable(self, apid, sids, kind="hk"):
        return self.request(apid, _TC[kind][3], _sids(sids))

    def report_structures(self, apid, sids, kind="hk"):
        return self.request(apid, _TC[kind][4], _sids(sids), _TM[kind][1])

    def one_shot(self, apid, sids, kind="hk"):
        return self.request(apid, _TC[kind][5], _sids(sids), _TM[kind][0])

    def append(self, apid, sid, parameters, kind="hk"):
        """Append ``parameters`` to structure ``sid`` (its periodic generation disabled)."""
        known = self._sets[kind].get(sid)
        if known is not None:
            self.learn(sid, known + list(parameters), kind)
        data = APPEND.pack({"sid": sid, "parameters": list(parameters), "groups": []})
        return self.request(apid, _TC[kind][6], data)

    def modify_interval(self, apid, intervals, kind="hk"):
        """``intervals`` maps SID -> new collection interval."""
        items = [{"sid": s, "interval": i} for s, i in intervals.items()]
        return self.request(apid, _TC[kind][7], INTERVALS.pack({"items": items}))

    def report_properties(self, apid, sids, kind="hk"):
        return self.request(apid, _TC[kind][8], _sids(sids), _TM[kind][2])

    # functional reporting: ``hk`` and ``diag`` map SIDs to (enabled, collection interval)

    def apply_functional(self, apid, ids):
        data = FUNCTIONAL_IDS.pack({"ids": list(ids)})
        return self.request(apid, TC_HK_APPLY_FUNCTIONAL_REPORTING, data)

    def _functional(self, apid, message_type, fid, hk, diag):
        data = FUNCTIONAL.pack(
            {"id": fid, "hk": _definitions(hk or {}), "diag": _definitions(diag or {})}
        )
        return self.request(apid, message_type, data)

    def create_functional(self, apid, fid, hk=None, diag=None):
        return self._functional(apid, TC_HK_CREATE_FUNCTIONAL_REPORTING, fid, hk, diag)

    def delete_functional(self, apid, ids):
        """Delete the definitions ``ids`` (an empty list: every definition)."""
        data = FUNCTIONAL_IDS.pack({"ids": list(ids)})
        return self.request(apid, TC_HK_DELETE_FUNCTIONAL_REPORTING, data)

    def report_functional(self, apid, ids=()):
        """Report the definitions ``ids`` (none: every definition) in one TM[3,41]."""
        data = FUNCTIONAL_IDS.pack({"ids": list(ids)})
        return self.request(
            apid, TC_HK_REPORT_FUNCTIONAL_REPORTING, data, TM_HK_FUNCTIONAL_REPORTING_REPORT
        )

    def add_to_functional(self, apid, fid, hk=None, diag=None):
        return self._functional(apid, TC_HK_ADD_TO_FUNCTIONAL_REPORTING, fid, hk, diag)

    def remove_from_functional(self, apid, fid, hk=(), diag=()):
        data = FUNCTIONAL_REMOVE.pack({"id": fid, "hk": list(hk), "diag": list(diag)})
        return self.request(apid, TC_HK_REMOVE_FROM_FUNCTIONAL_REPORTING, data)

    def modify_functional(self, apid, fid, hk=None, diag=None):
        return self._functional(apid, TC_HK_MODIFY_FUNCTIONAL_REPORTING_PERIODS, fid, hk, diag)

    # -------------------------------------------------------------------------- reports

    def kind_of(self, tm):
        """The set a report or structure TM belongs to: 'hk' or 'diag'."""
        return "diag" if tm.subtype in _DIAG_SUBTYPES else "hk"

    def decode_structure(self, tm):
        out = STRUCTURE_REPORT.unpack(tm.data)
        out["enabled"] = bool(out["enabled"])
        self.learn(out["sid"], out["parameters"], self.kind_of(tm))
        return out

    def decode_properties(self, tm):
        items = PROPERTIES_REPORT.unpack(tm.data)["items"]
        for i in items:
            i["enabled"] = bool(i["enabled"])
        return {"items": items}

    def decode_functional(self, tm):
        out = {}
        for item in FUNCTIONAL_REPORT.unpack(tm.data)["items"]:
            out[item["id"]] = {
                kind: {e["sid"]: (bool(e["enabled"]), e["interval"]) for e in item[kind]}
                for kind in KINDS
            }
        return {"definitions": out}

    def decode_report(self, tm):
        kind = self.kind_of(tm)
        sid = SID_ONLY.unpack(tm.data, False)["sid"]
        pids = self._sets[kind].get(sid)
        if pids is None:
            return {"sid": sid, "raw": bytes(tm.data[2:])}
        layout = self._layouts.get((kind, sid))
        if layout is None:
            layout = Structure(
                [("sid", STRUCTURE_ID)] + [(i, self.types(p)) for i, p in enumerate(pids)]
            )
            self._layouts[(kind, sid)] = layout
        raw = layout.unpack(tm.data)
        values = {}
        for i, pid in enumerate(pids):
            values[self.names(pid) if self.names else pid] = raw[i]
        return {"sid": sid, "values": values}
