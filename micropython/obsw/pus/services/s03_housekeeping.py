"""ST[03] housekeeping: report structures, periodic and one-shot parameter reports.

Collection intervals count minimum sampling intervals, which are the application process's
cycles (``ApplicationProcess.tick``). A request naming several structures is checked as a
whole first: if one of them is invalid, the start of execution fails with its ID in the
failure data and nothing is changed. Super-commutated groups are not supported (NFA must
be 0). The structures and their generation status persist in the context store.
"""

from obsw.pus.messages import (
    SERVICE_HOUSEKEEPING,
    TC_HK_CREATE_HK_STRUCTURE,
    TC_HK_DELETE_HK_STRUCTURES,
    TC_HK_DISABLE_HK_REPORTS,
    TC_HK_ENABLE_HK_REPORTS,
    TC_HK_MODIFY_HK_INTERVAL,
    TC_HK_ONE_SHOT_HK,
    TC_HK_REPORT_HK_PERIODIC_PROPERTIES,
    TC_HK_REPORT_HK_STRUCTURES,
    TM_HK_HK_PERIODIC_PROPERTIES_REPORT,
    TM_HK_HK_REPORT,
    TM_HK_HK_STRUCTURE_REPORT,
)
from obsw.pus.services.base import (
    COLLECTION_INTERVAL,
    GENERATION_STATUS,
    HK_COUNT,
    PARAMETER_ID,
    STRUCTURE_ID,
    U16,
    Service,
    ServiceUser,
)
from obsw.pus.services.s01_verification import (
    FAILURE_REFUSED,
    FAILURE_UNKNOWN_ID,
    PusFailure,
)
from obsw.pus.structure import Repeated, Structure

SUPER_COMMUTATED = Repeated(
    HK_COUNT, [("repetitions", U16), ("parameters", Repeated(HK_COUNT, PARAMETER_ID))]
)
CREATE = Structure(
    [
        ("sid", STRUCTURE_ID),
        ("interval", COLLECTION_INTERVAL),
        ("parameters", Repeated(HK_COUNT, PARAMETER_ID)),
        ("groups", SUPER_COMMUTATED),
    ]
)
SIDS = Structure([("sids", Repeated(HK_COUNT, STRUCTURE_ID))])
INTERVALS = Structure(
    [("items", Repeated(HK_COUNT, [("sid", STRUCTURE_ID), ("interval", COLLECTION_INTERVAL)]))]
)
STRUCTURE_REPORT = Structure(
    [
        ("sid", STRUCTURE_ID),
        ("enabled", GENERATION_STATUS),
        ("interval", COLLECTION_INTERVAL),
        ("parameters", Repeated(HK_COUNT, PARAMETER_ID)),
        ("groups", SUPER_COMMUTATED),
    ]
)
PROPERTIES_REPORT = Structure(
    [
        (
            "items",
            Repeated(
                HK_COUNT,
                [
                    ("sid", STRUCTURE_ID),
                    ("enabled", GENERATION_STATUS),
                    ("interval", COLLECTION_INTERVAL),
                ],
            ),
        )
    ]
)
_SID_ONLY = Structure([("sid", STRUCTURE_ID)])


class ReportStructure:
    """A housekeeping parameter report structure and its periodic generation state."""

    __slots__ = ("sid", "interval", "parameters", "enabled", "countdown", "layout")

    def __init__(self, sid, interval, parameters, enabled, types):
        self.sid = sid
        self.interval = interval
        self.parameters = list(parameters)
        self.enabled = enabled
        self.countdown = interval
        fields = [("sid", STRUCTURE_ID)]
        for i, pid in enumerate(self.parameters):
            fields.append((i, types(pid)))
        self.layout = Structure(fields)


class Housekeeping(Service):
    """The service 3 provider, reading values from a parameter pool.

    ``initial`` lists structures as dicts (``sid``, ``interval``, ``parameters``,
    ``enabled``), e.g. the spacecraft database's; a saved context replaces them.
    """

    SERVICE = SERVICE_HOUSEKEEPING
    REPORTS = (TM_HK_HK_STRUCTURE_REPORT, TM_HK_HK_REPORT, TM_HK_HK_PERIODIC_PROPERTIES_REPORT)
    NAME = "s03"
    HANDLERS = (
        (TC_HK_CREATE_HK_STRUCTURE, "create"),
        (TC_HK_DELETE_HK_STRUCTURES, "delete"),
        (TC_HK_ENABLE_HK_REPORTS, "enable"),
        (TC_HK_DISABLE_HK_REPORTS, "disable"),
        (TC_HK_REPORT_HK_STRUCTURES, "report_structures"),
        (TC_HK_ONE_SHOT_HK, "one_shot"),
        (TC_HK_MODIFY_HK_INTERVAL, "modify_interval"),
        (TC_HK_REPORT_HK_PERIODIC_PROPERTIES, "report_properties"),
    )

    def __init__(self, pool, initial=(), max_structures=32, max_parameters=64):
        super().__init__()
        self.pool = pool
        self.max_structures = max_structures
        self.max_parameters = max_parameters
        self.structures = {}
        self.reports = 0
        for s in initial:
            self._add(s["sid"], s["interval"], s["parameters"], s.get("enabled", False))

    def _add(self, sid, interval, parameters, enabled):
        self.structures[sid] = ReportStructure(
            sid, interval, parameters, enabled, self.pool.type_of
        )

    # -------------------------------------------------------------------------- context

    def context(self):
        return [[s.sid, s.interval, s.parameters, s.enabled] for s in self.structures.values()]

    def restore(self, ctx):
        structures = self.structures
        self.structures = {}
        try:
            for sid, interval, params, enabled in ctx:
                self._add(sid, interval, params, enabled)
        except Exception:
            self.structures = structures
            raise

    # -------------------------------------------------------------------------- handlers

    def _known(self, sids):
        for sid in sids:
            if sid not in self.structures:
                raise PusFailure(
                    FAILURE_UNKNOWN_ID, "no structure %d" % sid, _SID_ONLY.pack({"sid": sid})
                )

    def create(self, req):
        tc = req.decode(CREATE)
        sid = tc["sid"]
        refused = None
        if sid in self.structures:
            refused = "structure %d exists" % sid
        elif len(self.structures) >= self.max_structures:
            refused = "%d structures already" % len(self.structures)
        elif tc["groups"]:
            refused = "super-commutated groups are not supported"
        elif tc["interval"] == 0:
            refused = "collection interval 0"
        elif len(tc["parameters"]) > self.max_parameters:
            refused = "more than %d parameters" % self.max_parameters
        if refused:
            raise PusFailure(FAILURE_REFUSED, refused, _SID_ONLY.pack({"sid": sid}))
        for pid in tc["parameters"]:
            if pid not in self.pool:
                raise PusFailure(FAILURE_UNKNOWN_ID, "no parameter %d" % pid, U16.pack(pid))
        req.start()
        self._add(sid, tc["interval"], tc["parameters"], False)
        self.persist()

    def delete(self, req):
        sids = req.decode(SIDS)["sids"]
        self._known(sids)
        for sid in sids:
            if self.structures[sid].enabled:
                raise PusFailure(
                    FAILURE_REFUSED, "structure %d is enabled" % sid, _SID_ONLY.pack({"sid": sid})
                )
        req.start()
        for sid in sids:
            del self.structures[sid]
        self.persist()

    def _set_enabled(self, req, enabled):
        sids = req.decode(SIDS)["sids"]
        self._known(sids)
        req.start()
        for sid in sids:
            s = self.structures[sid]
            if enabled and not s.enabled:
                s.countdown = s.interval
            s.enabled = enabled
        self.persist()

    def enable(self, req):
        self._set_enabled(req, True)

    def disable(self, req):
        self._set_enabled(req, False)

    def report_structures(self, req):
        sids = req.decode(SIDS)["sids"]
        self._known(sids)
        for sid in sids:
            s = self.structures[sid]
            data = STRUCTURE_REPORT.pack(
                {
                    "sid": sid,
                    "enabled": 1 if s.enabled else 0,
                    "interval": s.interval,
                    "parameters": s.parameters,
                    "groups": [],
                }
            )
            req.report(TM_HK_HK_STRUCTURE_REPORT, data)

    def one_shot(self, req):
        sids = req.decode(SIDS)["sids"]
        self._known(sids)
        req.start()
        for sid in sids:
            self.generate(sid, req.source)

    def modify_interval(self, req):
        items = req.decode(INTERVALS)["items"]
        self._known([i["sid"] for i in items])
        for i in items:
            if i["interval"] == 0:
                raise PusFailure(
                    FAILURE_REFUSED, "collection interval 0", _SID_ONLY.pack({"sid": i["sid"]})
                )
        req.start()
        for i in items:
            s = self.structures[i["sid"]]
            s.interval = i["interval"]
            if s.countdown > s.interval:
                s.countdown = s.interval
        self.persist()

    def report_properties(self, req):
        sids = req.decode(SIDS)["sids"]
        self._known(sids)
        items = []
        for sid in sids:
            s = self.structures[sid]
            items.append({"sid": sid, "enabled": 1 if s.enabled else 0, "interval": s.interval})
        req.report(TM_HK_HK_PERIODIC_PROPERTIES_REPORT, PROPERTIES_REPORT.pack({"items": items}))

    # -------------------------------------------------------------------------- reports

    def generate(self, sid, destination=0):
        """Send the parameter report of structure ``sid`` now."""
        s = self.structures[sid]
        values = {"sid": sid}
        get = self.pool.get
        for i, pid in enumerate(s.parameters):
            values[i] = get(pid)
        try:
            data = s.layout.pack(values)
        except ValueError:
            self.app.count("hk_unpackable")
            return None
        self.reports += 1
        return self.send(TM_HK_HK_REPORT, data, destination)

    def cyclic(self, now):
        for s in self.structures.values():
            if s.enabled:
                s.countdown -= 1
                if s.countdown <= 0:
                    s.countdown = s.interval
                    self.generate(s.sid)


class HousekeepingUser(ServiceUser):
    """The service 3 user; ``types(pid)`` gives a parameter's field type, ``names(pid)`` its
    name (both from the spacecraft database). Structures are learnt from the requests sent,
    the structure reports received, and ``known``."""

    SERVICE = SERVICE_HOUSEKEEPING
    DECODERS = (
        (TM_HK_HK_STRUCTURE_REPORT, "decode_structure"),
        (TM_HK_HK_REPORT, "decode_report"),
        (TM_HK_HK_PERIODIC_PROPERTIES_REPORT, "decode_properties"),
    )

    def __init__(self, types, names=None, known=()):
        super().__init__()
        self.types = types
        self.names = names
        self.structures = {}  # sid -> [pid]
        self._layouts = {}
        for s in known:
            self.learn(s["sid"], s["parameters"])

    def learn(self, sid, parameters):
        self.structures[sid] = list(parameters)
        self._layouts.pop(sid, None)

    def create(self, apid, sid, interval, parameters):
        self.learn(sid, parameters)
        data = CREATE.pack(
            {"sid": sid, "interval": interval, "parameters": list(parameters), "groups": []}
        )
        return self.request(apid, TC_HK_CREATE_HK_STRUCTURE, data)

    def delete(self, apid, sids):
        return self.request(apid, TC_HK_DELETE_HK_STRUCTURES, SIDS.pack({"sids": list(sids)}))

    def enable(self, apid, sids):
        return self.request(apid, TC_HK_ENABLE_HK_REPORTS, SIDS.pack({"sids": list(sids)}))

    def disable(self, apid, sids):
        return self.request(apid, TC_HK_DISABLE_HK_REPORTS, SIDS.pack({"sids": list(sids)}))

    def report_structures(self, apid, sids):
        data = SIDS.pack({"sids": list(sids)})
        return self.request(apid, TC_HK_REPORT_HK_STRUCTURES, data, TM_HK_HK_STRUCTURE_REPORT)

    def one_shot(self, apid, sids):
        return self.request(
            apid, TC_HK_ONE_SHOT_HK, SIDS.pack({"sids": list(sids)}), TM_HK_HK_REPORT
        )

    def modify_interval(self, apid, intervals):
        """``intervals`` maps SID -> new collection interval."""
        items = [{"sid": s, "interval": i} for s, i in intervals.items()]
        return self.request(apid, TC_HK_MODIFY_HK_INTERVAL, INTERVALS.pack({"items": items}))

    def report_properties(self, apid, sids):
        data = SIDS.pack({"sids": list(sids)})
        return self.request(
            apid, TC_HK_REPORT_HK_PERIODIC_PROPERTIES, data, TM_HK_HK_PERIODIC_PROPERTIES_REPORT
        )

    def decode_structure(self, tm):
        out = STRUCTURE_REPORT.unpack(tm.data)
        out["enabled"] = bool(out["enabled"])
        self.learn(out["sid"], out["parameters"])
        return out

    def decode_properties(self, tm):
        items = PROPERTIES_REPORT.unpack(tm.data)["items"]
        for i in items:
            i["enabled"] = bool(i["enabled"])
        return {"items": items}

    def decode_report(self, tm):
        sid = _SID_ONLY.unpack(tm.data, False)["sid"]
        pids = self.structures.get(sid)
        if pids is None:
            return {"sid": sid, "raw": bytes(tm.data[2:])}
        layout = self._layouts.get(sid)
        if layout is None:
            layout = Structure(
                [("sid", STRUCTURE_ID)] + [(i, self.types(p)) for i, p in enumerate(pids)]
            )
            self._layouts[sid] = layout
        raw = layout.unpack(tm.data)
        values = {}
        for i, pid in enumerate(pids):
            values[self.names(pid) if self.names else pid] = raw[i]
        return {"sid": sid, "values": values}
