"""ST[12] functional monitoring: definitions (FMON) that combine parameter monitoring checks;
``FunctionalOnBoardMonitoring`` serves every message type of service 12 (1 to 28).

An FMON names a list of PMONs, a minimum failing number, a validity condition and an event.
While the functional monitoring function and the FMON are enabled (and the parameter
monitoring function, without which functional monitoring does not run), its checking status
is evaluated every cycle after the PMONs: ``invalid`` when the validity parameter, masked,
differs from the expected value; otherwise ``failed`` when at least the minimum failing
number of its PMONs have a checking status out of limits (below low, above high, unexpected
value), else ``running``. Disabled, or with a function disabled, it is ``unchecked``. Each
transition to ``failed`` raises the FMON's event once (service 5 reports it, service 19 may
act on it), with the FMON ID as auxiliary data; the FMON stays enabled and fails again only
after it has recovered.

Requests (ECSS-E-ST-70-41C 6.12.4): TC[12,17]/[12,18] enable/disable the function (enabling
is refused while the parameter monitoring function is disabled; disabling that one disables
this one too); TC[12,19]/[12,20] enable/disable FMONs (a protected FMON cannot be disabled);
TC[12,21]/[12,22] protect/unprotect; TC[12,23] add (new FMONs are disabled and unprotected);
TC[12,24] delete (not an enabled one); TC[12,25] report definitions (TM[12,26]; no IDs: all);
TC[12,27] report statuses (TM[12,28]). A request is checked whole before anything changes:
an unknown FMON, PMON, parameter or event fails its start with ``FAILURE_UNKNOWN_ID``, a
contradiction with ``FAILURE_REFUSED`` (the FMON ID in the data). A PMON used by an FMON
cannot be deleted.
"""

from obsw.pus.messages import (
    TC_MON_ADD_FUNCTIONAL_MONITORING,
    TC_MON_DELETE_FUNCTIONAL_MONITORING,
    TC_MON_DISABLE_FUNCTIONAL_MONITORING,
    TC_MON_DISABLE_FUNCTIONAL_MONITORING_FUNCTION,
    TC_MON_ENABLE_FUNCTIONAL_MONITORING,
    TC_MON_ENABLE_FUNCTIONAL_MONITORING_FUNCTION,
    TC_MON_PROTECT_FUNCTIONAL_MONITORING,
    TC_MON_REPORT_FUNCTIONAL_MONITORING,
    TC_MON_REPORT_FUNCTIONAL_MONITORING_STATUS,
    TC_MON_UNPROTECT_FUNCTIONAL_MONITORING,
    TM_MON_FUNCTIONAL_MONITORING_REPORT,
    TM_MON_FUNCTIONAL_MONITORING_STATUS_REPORT,
)
from obsw.pus.services.base import PARAMETER_ID
from obsw.pus.services.s01_verification import FAILURE_REFUSED, FAILURE_UNKNOWN_ID, PusFailure
from obsw.pus.services.s12_layouts import (
    ABOVE_HIGH,
    BELOW_LOW,
    EMPTY,
    FMON_FAILED,
    FMON_ID,
    FMON_INVALID,
    FMON_RUNNING,
    FMON_UNCHECKED,
    fmon_layouts,
)
from obsw.pus.services.s12_monitoring import OnBoardMonitoring

_FAILING = (BELOW_LOW, ABOVE_HIGH)
_MEDIUM = 3


def _failure(code, msg, fmon):
    return PusFailure(code, msg, FMON_ID.pack(fmon))


class Fmon:
    """One functional monitoring definition and its state."""

    __slots__ = ("d", "enabled", "protected", "status")

    def __init__(self, d, enabled=False, protected=False):
        self.d = d  # the definition as the add request's item dict
        self.enabled = enabled
        self.protected = protected
        self.status = FMON_UNCHECKED


class FunctionalOnBoardMonitoring(OnBoardMonitoring):
    """The service 12 provider with functional monitoring (see the module text);
    ``fmon_capacity`` bounds the FMONs, ``max_pmons`` the PMONs of one."""

    REPORTS = OnBoardMonitoring.REPORTS + (
        TM_MON_FUNCTIONAL_MONITORING_REPORT,
        TM_MON_FUNCTIONAL_MONITORING_STATUS_REPORT,
    )
    HANDLERS = OnBoardMonitoring.HANDLERS + (
        (TC_MON_ENABLE_FUNCTIONAL_MONITORING_FUNCTION, "fmon_enable_function"),
        (TC_MON_DISABLE_FUNCTIONAL_MONITORING_FUNCTION, "fmon_disable_function"),
        (TC_MON_ENABLE_FUNCTIONAL_MONITORING, "fmon_enable"),
        (TC_MON_DISABLE_FUNCTIONAL_MONITORING, "fmon_disable"),
        (TC_MON_PROTECT_FUNCTIONAL_MONITORING, "fmon_protect"),
        (TC_MON_UNPROTECT_FUNCTIONAL_MONITORING, "fmon_unprotect"),
        (TC_MON_ADD_FUNCTIONAL_MONITORING, "fmon_add"),
        (TC_MON_DELETE_FUNCTIONAL_MONITORING, "fmon_delete"),
        (TC_MON_REPORT_FUNCTIONAL_MONITORING, "fmon_report_definitions"),
        (TC_MON_REPORT_FUNCTIONAL_MONITORING_STATUS, "fmon_report_status"),
    )

    def __init__(self, pool, events=None, capacity=32, batch=16, fmon_capacity=16, max_pmons=32):
        self.fmons = {}  # FMON ID -> Fmon (before the base class restores a saved context)
        self.fmon_function = True
        self.fmon_capacity = fmon_capacity
        self.max_pmons = max_pmons
        self.fmon_failures = 0  # transitions to failed
        super().__init__(pool, events, capacity, batch)

    # -------------------------------------------------------------------------- context

    def context(self):
        ctx = super().context()
        ctx["functional"] = {
            "function": self.fmon_function,
            "fmons": [[f.d, f.enabled, f.protected] for f in self.fmons.values()],
        }
        return ctx

    def restore(self, ctx):
        super().restore(ctx)
        saved = ctx.get("functional")
        if saved is None:
            return
        fmons = {}
        for d, enabled, protected in saved["fmons"]:
            self._check_fmon(d)
            fmons[d["fmon"]] = Fmon(d, bool(enabled), bool(protected))
        self.fmon_function = bool(saved["function"])
        self.fmons = fmons

    # -------------------------------------------------------------------------- hooks

    def user_of(self, pmon):
        for i, f in sorted(self.fmons.items()):
            if pmon is None or pmon in f.d["pmons"]:
                return i
        return None

    def functional_stop(self):
        self.fmon_function = False
        for f in self.fmons.values():
            f.status = FMON_UNCHECKED

    # -------------------------------------------------------------------------- checks

    def _check_fmon(self, d):
        fmon = d["fmon"]
        if d["validity_mask"] and d["validity"] not in self.pool:
            pid = d["validity"]
            raise PusFailure(FAILURE_UNKNOWN_ID, "no parameter %d" % pid, PARAMETER_ID.pack(pid))
        pmons = d["pmons"]
        if not pmons or len(pmons) > self.max_pmons or len(set(pmons)) != len(pmons):
            raise _failure(
                FAILURE_REFUSED, "1 to %d different PMONs expected" % self.max_pmons, fmon
            )
        for p in pmons:
            if p not in self.pmons:
                raise _failure(FAILURE_UNKNOWN_ID, "no PMON %d" % p, fmon)
        if not 1 <= d["failing"] <= len(pmons):
            raise _failure(
                FAILURE_REFUSED,
                "minimum failing number %d, expected 1 to %d" % (d["failing"], len(pmons)),
                fmon,
            )
        if d["event"] and self.events is not None and d["event"] not in self.events:
            raise _failure(FAILURE_UNKNOWN_ID, "no event %d" % d["event"], fmon)

    def _known_fmons(self, ids):
        for i in ids:
            if i not in self.fmons:
                raise _failure(FAILURE_UNKNOWN_ID, "no FMON %d" % i, i)
        return ids

    # -------------------------------------------------------------------------- handlers

    def fmon_enable_function(self, req):
        req.decode(EMPTY)
        if not self.function:
            raise PusFailure(FAILURE_REFUSED, "the parameter monitoring function is disabled")
        req.start()
        self.fmon_function = True
        self.persist()

    def fmon_disable_function(self, req):
        req.decode(EMPTY)
        req.start()
        self.functional_stop()
        self.persist()

    def _switch_fmons(self, req, enabled):
        ids = self._known_fmons(req.decode(fmon_layouts().ids)["ids"])
        if not enabled:
            for i in ids:
                if self.fmons[i].protected:
                    raise _failure(FAILURE_REFUSED, "FMON %d is protected" % i, i)
        req.start()
        for i in ids:
            f = self.fmons[i]
            f.enabled = enabled
            f.status = FMON_UNCHECKED
        self.persist()

    def fmon_enable(self, req):
        self._switch_fmons(req, True)

    def fmon_disable(self, req):
        self._switch_fmons(req, False)

    def _protect(self, req, protected):
        ids = self._known_fmons(req.decode(fmon_layouts().ids)["ids"])
        req.start()
        for i in ids:
            self.fmons[i].protected = protected
        self.persist()

    def fmon_protect(self, req):
        self._protect(req, True)

    def fmon_unprotect(self, req):
        self._protect(req, False)

    def fmon_add(self, req):
        items = req.decode(fmon_layouts().add)["items"]
        if len(self.fmons) + len(items) > self.fmon_capacity:
            raise PusFailure(FAILURE_REFUSED, "at most %d FMONs" % self.fmon_capacity)
        seen = set()
        for d in items:
            if d["fmon"] in self.fmons or d["fmon"] in seen:
                raise _failure(FAILURE_REFUSED, "FMON %d exists" % d["fmon"], d["fmon"])
            seen.add(d["fmon"])
            self._check_fmon(d)
        req.start()
        for d in items:
            self.fmons[d["fmon"]] = Fmon(d)
        self.persist()

    def fmon_delete(self, req):
        ids = self._known_fmons(req.decode(fmon_layouts().ids)["ids"])
        for i in ids:
            if self.fmons[i].enabled:
                raise _failure(FAILURE_REFUSED, "FMON %d is enabled" % i, i)
        req.start()
        for i in ids:
            del self.fmons[i]
        self.persist()

    def fmon_report_definitions(self, req):
        ids = self._known_fmons(req.decode(fmon_layouts().ids)["ids"]) or sorted(self.fmons)
        req.start()
        items = []
        for i in ids:
            f = self.fmons[i]
            d = dict(f.d)
            d["enabled"] = 1 if f.enabled else 0
            d["protected"] = 1 if f.protected else 0
            items.append(d)
        data = fmon_layouts().report.pack({"items": items})
        req.report(TM_MON_FUNCTIONAL_MONITORING_REPORT, data)

    def fmon_report_status(self, req):
        req.decode(EMPTY)
        req.start()
        items = [
            {
                "fmon": i,
                "protected": 1 if f.protected else 0,
                "enabled": 1 if f.enabled else 0,
                "checking": f.status,
            }
            for i, f in sorted(self.fmons.items())
        ]
        data = fmon_layouts().status.pack({"items": items})
        req.report(TM_MON_FUNCTIONAL_MONITORING_STATUS_REPORT, data)

    # -------------------------------------------------------------------------- evaluation

    def _fmon_status(self, f):
        d = f.d
        if d["validity_mask"]:
            valid = int(self.pool.get(d["validity"])) & d["validity_mask"] == d["validity_value"]
            if not valid:
                return FMON_INVALID
        failing = 0
        for p in d["pmons"]:
            m = self.pmons.get(p)
            if m is not None and m.status in _FAILING:
                failing += 1
        return FMON_FAILED if failing >= d["failing"] else FMON_RUNNING

    def functional_cycle(self):
        running = self.fmon_function and self.function
        for key in sorted(self.fmons):
            f = self.fmons[key]
            if not (running and f.enabled):
                f.status = FMON_UNCHECKED
                continue
            status = self._fmon_status(f)
            if status == FMON_FAILED and f.status != FMON_FAILED:
                self.fmon_failures += 1
                self._raise_fmon(f.d)
            f.status = status

    def _raise_fmon(self, d):
        event = d["event"]
        if not event:
            return
        severity = _MEDIUM
        if self.events is not None and event in self.events:
            severity = self.events[event].severity
        self.raised += 1
        self.app.event(event, severity, FMON_ID.pack(d["fmon"]))
