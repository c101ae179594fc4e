"""ST[12] on-board monitoring: parameter monitoring definitions checked every few cycles.

Each enabled definition (PMON) samples its parameter every ``interval`` cycles of the
application process. If its validity parameter, masked, differs from the expected value the
check is invalid; otherwise an expected-value, limit or delta check gives a checking status
(``obsw.pus.services.s12_layouts``). A status is confirmed after ``repetitions`` equal
results in a row (invalid and unchecked at once); a confirmed change is a check transition.
Transitions are sent as TM[12,12] at the end of the cycle, or gathered up to the maximum
transition reporting delay (in cycles); a transition out of limits raises the check's event
through the application process (service 5 reports it, service 19 may act on it), with the
PMON ID and the parameter ID as auxiliary data. New definitions are disabled; disabling
one makes it unchecked. An enabled definition cannot be deleted, nor every definition
while the monitoring function is enabled, nor a PMON that a functional monitoring
definition uses. Definitions persist in the context store. Functional monitoring
(TC[12,17] to TM[12,28]) is ``obsw.pus.services.s12_functional``, a subclass of this provider
(a board that needs parameter monitoring only keeps its heap).

Limits are raw values of the parameter's own type, as the standard's messages carry them:
the ground converts engineering limits to raw ones (``obsw.pus.calibration``), so no
calibration runs on board for a check.
"""

from obsw.pus.messages import (
    SERVICE_ON_BOARD_MONITORING,
    TC_MON_ADD_PARAMETER_MONITORING,
    TC_MON_CHANGE_TRANSITION_DELAY,
    TC_MON_DELETE_ALL_PARAMETER_MONITORING,
    TC_MON_DELETE_PARAMETER_MONITORING,
    TC_MON_DISABLE_PARAMETER_MONITORING,
    TC_MON_DISABLE_PARAMETER_MONITORING_FUNCTION,
    TC_MON_ENABLE_PARAMETER_MONITORING,
    TC_MON_ENABLE_PARAMETER_MONITORING_FUNCTION,
    TC_MON_MODIFY_PARAMETER_MONITORING,
    TC_MON_REPORT_OUT_OF_LIMITS,
    TC_MON_REPORT_PARAMETER_MONITORING,
    TC_MON_REPORT_PARAMETER_MONITORING_STATUS,
    TM_MON_CHECK_TRANSITION_REPORT,
    TM_MON_OUT_OF_LIMITS_REPORT,
    TM_MON_PARAMETER_MONITORING_REPORT,
    TM_MON_PARAMETER_MONITORING_STATUS_REPORT,
)
from obsw.pus.services.base import PARAMETER_ID, Service
from obsw.pus.services.s01_verification import FAILURE_REFUSED, FAILURE_UNKNOWN_ID, PusFailure
from obsw.pus.services.s12_layouts import (
    ABOVE_HIGH,
    BELOW_LOW,
    CHECK_DELTA,
    CHECK_EXPECTED_VALUE,
    CHECK_LIMIT,
    DELAY_LAYOUT,
    EMPTY,
    IDS,
    INVALID,
    PMON_ID,
    STATUS_REPORT,
    UNCHECKED,
    WITHIN,
    Layouts,
)

_SPEC = {
    CHECK_EXPECTED_VALUE: ("mask", "expected", "event"),
    CHECK_LIMIT: ("low", "low_event", "high", "high_event"),
    CHECK_DELTA: ("low", "low_event", "high", "high_event", "consecutive"),
}
_HEAD = ("pmon", "parameter", "validity", "validity_mask", "validity_value", "interval")
_MEDIUM = 3


class Pmon:
    """One parameter monitoring definition and its checking state."""

    __slots__ = (
        "d",
        "enabled",
        "countdown",
        "status",
        "candidate",
        "count",
        "last",
        "deltas",
        "transition",
    )

    def __init__(self, d, enabled=False):
        self.d = d  # the definition as the add request's item dict
        self.enabled = enabled
        self.reset()

    def reset(self):
        self.countdown = 1
        self.status = UNCHECKED
        self.candidate = UNCHECKED
        self.count = 0
        self.last = None
        self.deltas = []
        self.transition = None


def _pmon_failure(code, msg, pmon):
    return PusFailure(code, msg, PMON_ID.pack(pmon))


class OnBoardMonitoring(Service):
    """The service 12 provider on a parameter pool (see the module text).

    ``events`` maps event IDs to the database's EventDefs (for their severities; events
    not listed are refused). ``capacity`` bounds the definitions, ``batch`` the transitions
    in one report.
    """

    SERVICE = SERVICE_ON_BOARD_MONITORING
    REPORTS = (
        TM_MON_PARAMETER_MONITORING_REPORT,
        TM_MON_OUT_OF_LIMITS_REPORT,
        TM_MON_CHECK_TRANSITION_REPORT,
        TM_MON_PARAMETER_MONITORING_STATUS_REPORT,
    )
    NAME = "s12"
    HANDLERS = (
        (TC_MON_ENABLE_PARAMETER_MONITORING, "enable"),
        (TC_MON_DISABLE_PARAMETER_MONITORING, "disable"),
        (TC_MON_CHANGE_TRANSITION_DELAY, "change_delay"),
        (TC_MON_DELETE_ALL_PARAMETER_MONITORING, "delete_all"),
        (TC_MON_ADD_PARAMETER_MONITORING, "add"),
        (TC_MON_DELETE_PARAMETER_MONITORING, "delete"),
        (TC_MON_MODIFY_PARAMETER_MONITORING, "modify"),
        (TC_MON_REPORT_PARAMETER_MONITORING, "report_definitions"),
        (TC_MON_REPORT_OUT_OF_LIMITS, "report_out_of_limits"),
        (TC_MON_REPORT_PARAMETER_MONITORING_STATUS, "report_status"),
        (TC_MON_ENABLE_PARAMETER_MONITORING_FUNCTION, "enable_function"),
        (TC_MON_DISABLE_PARAMETER_MONITORING_FUNCTION, "disable_function"),
    )

    def __init__(self, pool, events=None, capacity=32, batch=16):
        super().__init__()
        self.pool = pool
        self.events = events
        self.capacity = capacity
        self.batch = batch
        self.layouts = Layouts(pool.type_of)
        self.pmons = {}  # PMON ID -> Pmon
        self.function = True
        self.delay = 0
        self.pending = []  # transitions not yet reported
        self._age = 0
        self.transitions = 0
        self.raised = 0

    # -------------------------------------------------------------------------- context

    def context(self):
        return {
            "function": self.function,
            "delay": self.delay,
            "pmons": [[m.d, m.enabled] for m in self.pmons.values()],
        }

    def restore(self, ctx):
        pmons = {}
        for d, enabled in ctx["pmons"]:
            self.check_definition(d)
            pmons[d["pmon"]] = Pmon(d, bool(enabled))
        self.function = bool(ctx["function"])
        self.delay = int(ctx["delay"])
        self.pmons = pmons

    # -------------------------------------------------------------------------- checks

    def check_definition(self, d):
        """Raise PusFailure unless definition ``d`` can be monitored."""
        pmon = d["pmon"]
        for key in ("parameter", "validity"):
            if key == "validity" and not d.get("validity_mask", 1):
                continue
            pid = d[key]
            if pid not in self.pool:
                raise PusFailure(
                    FAILURE_UNKNOWN_ID, "no parameter %d" % pid, PARAMETER_ID.pack(pid)
                )
        if d.get("interval", 1) == 0 or d["repetitions"] == 0:
            raise _pmon_failure(FAILURE_REFUSED, "interval and repetitions must be > 0", pmon)
        check = d["check"]
        for key in _SPEC[check]:
            if key.endswith("event") and d[key] and self.events is not None:
                if d[key] not in self.events:
                    raise _pmon_failure(FAILURE_UNKNOWN_ID, "no event %d" % d[key], pmon)
        if check == CHECK_EXPECTED_VALUE:
            if self.pool.type_of(d["parameter"]).ptc not in (1, 2, 3, 4):
                raise _pmon_failure(FAILURE_REFUSED, "expected value of a non-integer", pmon)
        elif d["low"] > d["high"]:
            raise _pmon_failure(FAILURE_REFUSED, "low above high", pmon)
        if check == CHECK_DELTA and d["consecutive"] == 0:
            raise _pmon_failure(FAILURE_REFUSED, "no consecutive deltas", pmon)

    def _known(self, ids):
        for i in ids:
            if i not in self.pmons:
                raise _pmon_failure(FAILURE_UNKNOWN_ID, "no PMON %d" % i, i)
        return ids

    # -------------------------------------------------------------------------- handlers

    def add(self, req):
        items = req.decode(self.layouts.add)["items"]
        if len(self.pmons) + len(items) > self.capacity:
            raise PusFailure(FAILURE_REFUSED, "at most %d definitions" % self.capacity)
        seen = set()
        for d in items:
            if d["pmon"] in self.pmons or d["pmon"] in seen:
                raise _pmon_failure(FAILURE_REFUSED, "PMON %d exists" % d["pmon"], d["pmon"])
            seen.add(d["pmon"])
            self.check_definition(d)
        req.start()
        for d in items:
            self.pmons[d["pmon"]] = Pmon(d)
        self.persist()

    def delete(self, req):
        ids = self._known(req.decode(IDS)["ids"])
        for i in ids:
            if self.pmons[i].enabled:
                raise _pmon_failure(FAILURE_REFUSED, "PMON %d is enabled" % i, i)
            fmon = self.user_of(i)
            if fmon is not None:
                raise _pmon_failure(FAILURE_REFUSED, "FMON %d uses PMON %d" % (fmon, i), i)
        req.start()
        for i in ids:
            del self.pmons[i]
        self.persist()

    def delete_all(self, req):
        req.decode(EMPTY)
        if self.function:
            raise PusFailure(FAILURE_REFUSED, "the monitoring function is enabled")
        if self.user_of(None) is not None:
            raise PusFailure(FAILURE_REFUSED, "functional monitoring definitions use the PMONs")
        req.start()
        self.pmons = {}
        self.persist()

    def modify(self, req):
        items = req.decode(self.layouts.modify)["items"]
        self._known([d["pmon"] for d in items])
        new = []
        for d in items:
            old = self.pmons[d["pmon"]].d
            if d["parameter"] != old["parameter"]:
                raise _pmon_failure(FAILURE_REFUSED, "PMON monitors another parameter", d["pmon"])
            merged = {k: old[k] for k in _HEAD}
            merged.update(d)
            self.check_definition(merged)
            new.append(merged)
        req.start()
        for d in new:
            m = self.pmons[d["pmon"]]
            m.d = d
            m.reset()
        self.persist()

    def _switch(self, req, enabled):
        ids = self._known(req.decode(IDS)["ids"])
        req.start()
        for i in ids:
            m = self.pmons[i]
            if m.enabled != enabled:
                m.enabled = enabled
                m.reset()
        self.persist()

    def enable(self, req):
        self._switch(req, True)

    def disable(self, req):
        self._switch(req, False)

    def change_delay(self, req):
        delay = req.decode(DELAY_LAYOUT)["delay"]
        req.start()
        self.delay = delay
        self.persist()

    def _function(self, req, enabled):
        req.decode(EMPTY)
        req.start()
        if enabled != self.function:
            for m in self.pmons.values():
                m.reset()
        self.function = enabled
        if not enabled:
            self.functional_stop()
        self.persist()

    def enable_function(self, req):
        self._function(req, True)

    def disable_function(self, req):
        self._function(req, False)

    def report_definitions(self, req):
        ids = self._known(req.decode(IDS)["ids"]) or sorted(self.pmons)
        items = []
        for i in ids:
            m = self.pmons[i]
            d = dict(m.d)
            d["enabled"] = 1 if m.enabled else 0
            items.append(d)
        data = self.layouts.report.pack({"delay": self.delay, "items": items})
        req.report(TM_MON_PARAMETER_MONITORING_REPORT, data)

    def report_out_of_limits(self, req):
        req.decode(EMPTY)
        items = [
            m.transition
            for _, m in sorted(self.pmons.items())
            if m.status in (BELOW_LOW, ABOVE_HIGH) and m.transition is not None
        ]
        data = self.layouts.transitions.pack({"items": items})
        req.report(TM_MON_OUT_OF_LIMITS_REPORT, data)

    def report_status(self, req):
        req.decode(EMPTY)
        items = [
            {"pmon": i, "enabled": 1 if m.enabled else 0} for i, m in sorted(self.pmons.items())
        ]
        req.report(TM_MON_PARAMETER_MONITORING_STATUS_REPORT, STATUS_REPORT.pack({"items": items}))

    # -------------------------------------------------------------------------- hooks

    def user_of(self, pmon):
        """The ID of a functional monitoring definition that uses PMON ``pmon`` (any PMON:
        None), or None; none here (``obsw.pus.services.s12_functional`` has them)."""
        return None

    def functional_stop(self):
        """The parameter monitoring function was disabled (functional monitoring stops)."""

    def functional_cycle(self):
        """Evaluate functional monitoring after the PMONs of a cycle."""

    # -------------------------------------------------------------------------- monitoring

    def _evaluate(self, m):
        """(status, value, limit) of one sample of ``m``."""
        d = m.d
        get = self.pool.get
        check = d["check"]
        if (
            d["validity_mask"]
            and int(get(d["validity"])) & d["validity_mask"] != d["validity_value"]
        ):
            value = get(d["parameter"]) if check != CHECK_DELTA else 0.0
            return INVALID, value, d["expected"] if check == CHECK_EXPECTED_VALUE else value
        value = get(d["parameter"])
        if check == CHECK_EXPECTED_VALUE:
            ok = int(value) & d["mask"] == d["expected"]
            return (WITHIN if ok else BELOW_LOW), value, d["expected"]
        if check == CHECK_DELTA:
            last = m.last
            m.last = value
            if last is None:
                return UNCHECKED, 0.0, d["low"]
            m.deltas.append(value - last)
            if len(m.deltas) > d["consecutive"]:
                m.deltas.pop(0)
            if len(m.deltas) < d["consecutive"]:
                return UNCHECKED, 0.0, d["low"]
            value = sum(m.deltas) / len(m.deltas)
        if value < d["low"]:
            return BELOW_LOW, value, d["low"]
        if value > d["high"]:
            return ABOVE_HIGH, value, d["high"]
        if m.status == ABOVE_HIGH:
            return WITHIN, value, d["high"]
        return WITHIN, value, d["low"]

    def sample(self, m):
        """Check ``m`` once; returns the transition if its status changed, else None."""
        status, value, limit = self._evaluate(m)
        if status == m.candidate:
            m.count += 1
        else:
            m.candidate = status
            m.count = 1
        need = m.d["repetitions"] if status not in (UNCHECKED, INVALID) else 1
        if m.count < need or status == m.status:
            return None
        d = m.d
        entry = {
            "pmon": d["pmon"],
            "parameter": d["parameter"],
            "check": d["check"],
            "value": value,
            "limit": limit,
            "previous": m.status,
            "current": status,
            "time": self.app.time(),
        }
        if d["check"] == CHECK_EXPECTED_VALUE:
            entry["mask"] = d["mask"]
        m.status = status
        m.transition = entry
        self.transitions += 1
        self.pending.append(entry)
        if status in (BELOW_LOW, ABOVE_HIGH):
            self._raise(d, status)
        return entry

    def _raise(self, d, status):
        if d["check"] == CHECK_EXPECTED_VALUE:
            event = d["event"]
        else:
            event = d["low_event"] if status == BELOW_LOW else d["high_event"]
        if not event:
            return
        severity = _MEDIUM
        if self.events is not None:
            ev = self.events.get(event)
            if ev is not None:
                severity = ev.severity
        self.raised += 1
        self.app.event(
            event, severity, PMON_ID.pack(d["pmon"]) + PARAMETER_ID.pack(d["parameter"])
        )

    def cyclic(self, now):
        if self.function:
            pmons = self.pmons
            for key in sorted(pmons):  # in ID order on every port (dict order is not)
                m = pmons[key]
                if not m.enabled:
                    continue
                m.countdown -= 1
                if m.countdown > 0:
                    continue
                m.countdown = m.d["interval"]
                try:
                    self.sample(m)
                except (KeyError, TypeError, ValueError):
                    self.app.count("monitoring_errors")
        try:
            self.functional_cycle()
        except (KeyError, TypeError, ValueError):
            self.app.count("monitoring_errors")
        self.flush()

    def flush(self, force=False):
        """Send the pending transitions if the reporting delay has passed."""
        if not self.pending:
            self._age = 0
            return
        if not force and self._age < self.delay and len(self.pending) < self.batch:
            self._age += 1
            return
        items = self.pending[: self.batch]
        del self.pending[: self.batch]
        self._age = 0
        try:
            data = self.layouts.transitions.pack({"items": items})
        except ValueError:
            self.app.count("monitoring_errors")
            return
        self.send(TM_MON_CHECK_TRANSITION_REPORT, data)
