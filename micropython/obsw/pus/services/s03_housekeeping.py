"""ST[03] housekeeping: report structures, periodic and one-shot parameter reports.

Two sets of parameter report structures (ECSS-E-ST-70-41C 6.3): housekeeping structures,
reported in TM[3,25], and diagnostic structures, reported in TM[3,26]; every request of one
has its twin for the other (create 1/2, delete 3/4, enable 5/7, disable 6/8, report the
structures 9/11 -> 10/12, one-shot 27/28, append 29/30, modify the interval 31/32, report the
periodic generation properties 33/34 -> 35/36). Collection intervals count minimum sampling
intervals, which for both sets are the application process's cycles
(``ApplicationProcess.tick``). Parameter functional reporting (37 to 44) is in
``s03_functional``.

A request is checked as a whole first: if a structure or parameter it names is unknown, the
start of execution fails with ``FAILURE_UNKNOWN_ID`` and the ID in the failure data; if it
contradicts the state (an ID in use, an enabled structure deleted or appended to, interval 0,
a parameter already in the structure, a full table), with ``FAILURE_REFUSED``; nothing is
changed. Super-commutated groups are not supported (NFA must be 0). The structures, their
generation status and the functional reporting definitions persist in the context store.
"""

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
from obsw.pus.services.base import STRUCTURE_ID, U16, Service
from obsw.pus.services.s01_verification import (
    FAILURE_EXECUTION,
    FAILURE_REFUSED,
    FAILURE_UNKNOWN_ID,
    PusFailure,
)
from obsw.pus.services.s03_functional import FunctionalReporting
from obsw.pus.services.s03_layouts import (
    APPEND,
    CREATE,
    INTERVALS,
    PROPERTIES_REPORT,
    SID_ONLY,
    SIDS,
    STRUCTURE_REPORT,
)
from obsw.pus.services.s03_user import HousekeepingUser  # noqa: F401 (its home until now)
from obsw.pus.structure import Structure

# what differs between the two sets: the reports each one's requests cause
_REPORTS = {
    "hk": (TM_HK_HK_REPORT, TM_HK_HK_STRUCTURE_REPORT, TM_HK_HK_PERIODIC_PROPERTIES_REPORT),
    "diag": (
        TM_HK_DIAG_REPORT,
        TM_HK_DIAG_STRUCTURE_REPORT,
        TM_HK_DIAG_PERIODIC_PROPERTIES_REPORT,
    ),
}


def _sid_failure(code, text, sid):
    return PusFailure(code, text, SID_ONLY.pack({"sid": sid}))


class ReportStructure:
    """A parameter report structure and its periodic generation state."""

    __slots__ = ("sid", "interval", "parameters", "enabled", "countdown", "layout")

    def __init__(self, sid, interval, parameters, enabled, types):
        self.sid = sid
        self.interval = interval
        self.parameters = list(parameters)
        self.enabled = enabled
        self.countdown = interval
        self.relayout(types)

    def relayout(self, types):
        fields = [("sid", STRUCTURE_ID)]
        for i, pid in enumerate(self.parameters):
            fields.append((i, types(pid)))
        self.layout = Structure(fields)


class Housekeeping(FunctionalReporting, Service):
    """The service 3 provider, reading values from a parameter pool.

    ``initial`` and ``diagnostic`` list housekeeping and diagnostic structures as dicts
    (``sid``, ``interval``, ``parameters``, ``enabled``), e.g. the spacecraft database's; a
    saved context replaces them. ``structures`` and ``diagnostics`` map SIDs to them.
    """

    SERVICE = SERVICE_HOUSEKEEPING
    REPORTS = (
        TM_HK_HK_STRUCTURE_REPORT,
        TM_HK_DIAG_STRUCTURE_REPORT,
        TM_HK_HK_REPORT,
        TM_HK_DIAG_REPORT,
        TM_HK_HK_PERIODIC_PROPERTIES_REPORT,
        TM_HK_DIAG_PERIODIC_PROPERTIES_REPORT,
        TM_HK_FUNCTIONAL_REPORTING_REPORT,
    )
    NAME = "s03"
    HANDLERS = (
        (TC_HK_CREATE_HK_STRUCTURE, "create"),
        (TC_HK_CREATE_DIAG_STRUCTURE, "create_diag"),
        (TC_HK_DELETE_HK_STRUCTURES, "delete"),
        (TC_HK_DELETE_DIAG_STRUCTURES, "delete_diag"),
        (TC_HK_ENABLE_HK_REPORTS, "enable"),
        (TC_HK_DISABLE_HK_REPORTS, "disable"),
        (TC_HK_ENABLE_DIAG_REPORTS, "enable_diag"),
        (TC_HK_DISABLE_DIAG_REPORTS, "disable_diag"),
        (TC_HK_REPORT_HK_STRUCTURES, "report_structures"),
        (TC_HK_REPORT_DIAG_STRUCTURES, "report_diag_structures"),
        (TC_HK_ONE_SHOT_HK, "one_shot"),
        (TC_HK_ONE_SHOT_DIAG, "one_shot_diag"),
        (TC_HK_APPEND_HK_PARAMETERS, "append"),
        (TC_HK_APPEND_DIAG_PARAMETERS, "append_diag"),
        (TC_HK_MODIFY_HK_INTERVAL, "modify_interval"),
        (TC_HK_MODIFY_DIAG_INTERVAL, "modify_diag_interval"),
        (TC_HK_REPORT_HK_PERIODIC_PROPERTIES, "report_properties"),
        (TC_HK_REPORT_DIAG_PERIODIC_PROPERTIES, "report_diag_properties"),
        (TC_HK_APPLY_FUNCTIONAL_REPORTING, "apply_functional"),
        (TC_HK_CREATE_FUNCTIONAL_REPORTING, "create_functional"),
        (TC_HK_DELETE_FUNCTIONAL_REPORTING, "delete_functional"),
        (TC_HK_REPORT_FUNCTIONAL_REPORTING, "report_functional"),
        (TC_HK_ADD_TO_FUNCTIONAL_REPORTING, "add_to_functional"),
        (TC_HK_REMOVE_FROM_FUNCTIONAL_REPORTING, "remove_from_functional"),
        (TC_HK_MODIFY_FUNCTIONAL_REPORTING_PERIODS, "modify_functional"),
    )

    def __init__(self, pool, initial=(), max_structures=32, max_parameters=64, diagnostic=()):
        super().__init__()
        self.pool = pool
        self.max_structures = max_structures
        self.max_parameters = max_parameters
        self.structures = {}
        self.diagnostics = {}
        self.sets = {"hk": self.structures, "diag": self.diagnostics}
        self.reports = 0
        self._functional_init()
        for kind, listed in (("hk", initial), ("diag", diagnostic)):
            for s in listed:
                self._add(kind, s["sid"], s["interval"], s["parameters"], s.get("enabled", False))

    def _add(self, kind, sid, interval, parameters, enabled):
        self.sets[kind][sid] = ReportStructure(
            sid, interval, parameters, enabled, self.pool.type_of
        )

    # -------------------------------------------------------------------------- context

    def context(self):
        out = {"functional": self.functional_context()}
        for kind, structures in self.sets.items():
            out[kind] = [[s.sid, s.interval, s.parameters, s.enabled] for s in structures.values()]
        return out

    def restore(self, ctx):
        if isinstance(ctx, list):  # saved before diagnostics: the housekeeping set alone
            ctx = {"hk": ctx}
        saved = (dict(self.structures), dict(self.diagnostics), self.functional)
        try:
            for kind in self.sets:
                self.sets[kind].clear()
                for sid, interval, params, enabled in ctx.get(kind, ()):
                    self._add(kind, sid, interval, params, enabled)
            self.restore_functional(ctx.get("functional", ()))
        except Exception:
            for structures, before in zip((self.structures, self.diagnostics), saved):
                structures.clear()
                structures.update(before)
            self.functional = saved[2]
            raise

    # -------------------------------------------------------------------------- checks

    def _known(self, kind, sids):
        for sid in sids:
            if sid not in self.sets[kind]:
                raise _sid_failure(FAILURE_UNKNOWN_ID, "no %s structure %d" % (kind, sid), sid)

    def _check_parameters(self, pids, already=()):
        for pid in pids:
            if pid not in self.pool:
                raise PusFailure(FAILURE_UNKNOWN_ID, "no parameter %d" % pid, U16.pack(pid))
        seen = set(already)
        for pid in pids:
            if pid in seen:
                raise PusFailure(
                    FAILURE_REFUSED, "parameter %d twice in the structure" % pid, U16.pack(pid)
                )
            seen.add(pid)

    # -------------------------------------------------------------------------- handlers

    def _create(self, req, kind):
        tc = req.decode(CREATE)
        sid = tc["sid"]
        structures = self.sets[kind]
        refused = None
        if sid in structures:
            refused = "%s structure %d exists" % (kind, sid)
        elif len(structures) >= self.max_structures:
            refused = "%d %s structures already" % (len(structures), kind)
        elif tc["groups"]:
            refused = "super-commutated groups are not supported"
        elif tc["interval"] == 0:
            refused = "collection interval 0"
        elif len(tc["parameters"]) > self.max_parameters:
            refused = "more than %d parameters" % self.max_parameters
        if refused:
            raise _sid_failure(FAILURE_REFUSED, refused, sid)
        self._check_parameters(tc["parameters"])
        req.start()
        self._add(kind, sid, tc["interval"], tc["parameters"], False)
        self.persist()

    def _delete(self, req, kind):
        sids = req.decode(SIDS)["sids"]
        self._known(kind, sids)
        structures = self.sets[kind]
        for sid in sids:
            if structures[sid].enabled:
                raise _sid_failure(
                    FAILURE_REFUSED, "%s structure %d is enabled" % (kind, sid), sid
                )
        req.start()
        for sid in sids:
            del structures[sid]
        self.persist()

    def _set_enabled(self, req, kind, enabled):
        sids = req.decode(SIDS)["sids"]
        self._known(kind, sids)
        req.start()
        for sid in sids:
            s = self.sets[kind][sid]
            self._set_properties(s, enabled, s.interval)
        self.persist()

    def _set_properties(self, s, enabled, interval):
        if enabled and not s.enabled:
            s.countdown = interval
        s.enabled = enabled
        s.interval = interval
        if s.countdown > interval:
            s.countdown = interval

    def _report_structures(self, req, kind):
        sids = req.decode(SIDS)["sids"]
        self._known(kind, sids)
        for sid in sids:
            s = self.sets[kind][sid]
            data = STRUCTURE_REPORT.pack(
                {
                    "sid": sid,
                    "enabled": 1 if s.enabled else 0,
                    "interval": s.interval,
                    "parameters": s.parameters,
                    "groups": [],
                }
            )
            req.report(_REPORTS[kind][1], data)

    def _one_shot(self, req, kind):
        sids = req.decode(SIDS)["sids"]
        self._known(kind, sids)
        req.start()
        lost = [sid for sid in sids if self.generate(sid, req.source, kind) is None]
        if lost:  # said with its reason by the application process's unsent listeners
            raise _sid_failure(FAILURE_EXECUTION, "no report of structure %d" % lost[0], lost[0])

    def _append(self, req, kind):
        tc = req.decode(APPEND)
        sid = tc["sid"]
        self._known(kind, [sid])
        s = self.sets[kind][sid]
        refused = None
        if s.enabled:
            refused = "%s structure %d is enabled" % (kind, sid)
        elif tc["groups"]:
            refused = "super-commutated groups are not supported"
        elif len(s.parameters) + len(tc["parameters"]) > self.max_parameters:
            refused = "more than %d parameters" % self.max_parameters
        if refused:
            raise _sid_failure(FAILURE_REFUSED, refused, sid)
        self._check_parameters(tc["parameters"], s.parameters)
        req.start()
        s.parameters += tc["parameters"]
        s.relayout(self.pool.type_of)
        self.persist()

    def _modify_interval(self, req, kind):
        items = req.decode(INTERVALS)["items"]
        self._known(kind, [i["sid"] for i in items])
        for i in items:
            if i["interval"] == 0:
                raise _sid_failure(FAILURE_REFUSED, "collection interval 0", i["sid"])
        req.start()
        for i in items:
            s = self.sets[kind][i["sid"]]
            self._set_properties(s, s.enabled, i["interval"])
        self.persist()

    def _report_properties(self, req, kind):
        sids = req.decode(SIDS)["sids"]
        self._known(kind, sids)
        items = []
        for sid in sids:
            s = self.sets[kind][sid]
            items.append({"sid": sid, "enabled": 1 if s.enabled else 0, "interval": s.interval})
        req.report(_REPORTS[kind][2], PROPERTIES_REPORT.pack({"items": items}))

    def create(self, req):
        self._create(req, "hk")

    def create_diag(self, req):
        self._create(req, "diag")

    def delete(self, req):
        self._delete(req, "hk")

    def delete_diag(self, req):
        self._delete(req, "diag")

    def enable(self, req):
        self._set_enabled(req, "hk", True)

    def disable(self, req):
        self._set_enabled(req, "hk", False)

    def enable_diag(self, req):
        self._set_enabled(req, "diag", True)

    def disable_diag(self, req):
        self._set_enabled(req, "diag", False)

    def report_structures(self, req):
        self._report_structures(req, "hk")

    def report_diag_structures(self, req):
        self._report_structures(req, "diag")

    def one_shot(self, req):
        self._one_shot(req, "hk")

    def one_shot_diag(self, req):
        self._one_shot(req, "diag")

    def append(self, req):
        self._append(req, "hk")

    def append_diag(self, req):
        self._append(req, "diag")

    def modify_interval(self, req):
        self._modify_interval(req, "hk")

    def modify_diag_interval(self, req):
        self._modify_interval(req, "diag")

    def report_properties(self, req):
        self._report_properties(req, "hk")

    def report_diag_properties(self, req):
        self._report_properties(req, "diag")

    # -------------------------------------------------------------------------- reports

    def generate(self, sid, destination=0, kind="hk"):
        """Send the parameter report of structure ``sid`` of ``kind`` ("hk", "diag") now."""
        s = self.sets[kind][sid]
        values = {"sid": sid}
        get = self.pool.get
        for i, pid in enumerate(s.parameters):
            values[i] = get(pid)
        try:
            data = s.layout.pack(values)
        except ValueError as e:
            self.app.count("hk_unpackable")
            t = _REPORTS[kind][0]
            self.app.unsent(t[0], t[1], "structure %d: %s" % (sid, self._why(s, values, e)))
            return None
        self.reports += 1
        return self.send(_REPORTS[kind][0], data, destination)

    def _why(self, s, values, error):
        """The parameter whose value the structure's layout refused, and why."""
        for i, pid in enumerate(s.parameters):
            try:
                self.pool.type_of(pid).check(values[i])
            except ValueError as e:
                return "parameter %d = %r: %s" % (pid, values[i], e)
        return str(error)

    def cyclic(self, now):
        for kind, structures in self.sets.items():
            for s in structures.values():
                if s.enabled:
                    s.countdown -= 1
                    if s.countdown <= 0:
                        s.countdown = s.interval
                        self.generate(s.sid, 0, kind)
