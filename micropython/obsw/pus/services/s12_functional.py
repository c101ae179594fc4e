"""ST[12] functional monitoring: definitions (FMON) that combine parameter monitoring checks.

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

from obsw.pus.services.base import PARAMETER_ID
from obsw.pus.services.s01_verification import FAILURE_REFUSED, FAILURE_UNKNOWN_ID, PusFailure
from obsw.pus.services.s12_layouts import (
    ABOVE_HIGH,
    BELOW_LOW,
    EMPTY,
    FMON_ADD,
    FMON_FAILED,
    FMON_ID,
    FMON_IDS,
    FMON_INVALID,
    FMON_REPORT,
    FMON_RUNNING,
    FMON_STATUS_REPORT,
    FMON_UNCHECKED,
)

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


class FunctionalMonitoring:
    """The FMONs of one ``OnBoardMonitoring`` provider (``mon``); its handlers take the
    provider's requests. ``capacity`` bounds the FMONs, ``max_pmons`` the PMONs of one."""

    def __init__(self, mon, capacity=16, max_pmons=32):
        self.mon = mon
        self.capacity = capacity
        self.max_pmons = max_pmons
        self.fmons = {}  # FMON ID -> Fmon
        self.function = True
        self.failures = 0  # transitions to failed

    # -------------------------------------------------------------------------- context

    def context(self):
        return {
            "function": self.function,
            "fmons": [[f.d, f.enabled, f.protected] for f in self.fmons.values()],
        }

    def restore(self, ctx):
        fmons = {}
        for d, enabled, protected in ctx["fmons"]:
            self._check(d)
            fmons[d["fmon"]] = Fmon(d, bool(enabled), bool(protected))
        self.function = bool(ctx["function"])
        self.fmons = fmons

    def uses(self, pmon):
        """The ID of an FMON that lists PMON ``pmon``, or None."""
        for i, f in sorted(self.fmons.items()):
            if pmon in f.d["pmons"]:
                return i
        return None

    # -------------------------------------------------------------------------- checks

    def _check(self, d):
        fmon = d["fmon"]
        mon = self.mon
        if d["validity_mask"] and d["validity"] not in mon.pool:
            pid = d["validity"]
            raise PusFailure(FAILURE_UNKNOWN_ID, "no parameter %d" % pid, PARAMETER_ID.pack(pid))
        pmons = d["pmons"]
        if not pmons or len(pmons) > self.max_pmons or len(set(pmons)) != len(pmons):
            raise _failure(
                FAILURE_REFUSED, "1 to %d different PMONs expected" % self.max_pmons, fmon
            )
        for p in pmons:
            if p not in mon.pmons:
                raise _failure(FAILURE_UNKNOWN_ID, "no PMON %d" % p, fmon)
        if not 1 <= d["failing"] <= len(pmons):
            raise _failure(
                FAILURE_REFUSED,
                "minimum failing number %d, expected 1 to %d" % (d["failing"], len(pmons)),
                fmon,
            )
        if d["event"] and mon.events is not None and d["event"] not in mon.events:
            raise _failure(FAILURE_UNKNOWN_ID, "no event %d" % d["event"], fmon)

    def _known(self, ids):
        for i in ids:
            if i not in self.fmons:
                raise _failure(FAILURE_UNKNOWN_ID, "no FMON %d" % i, i)
        return ids

    # -------------------------------------------------------------------------- handlers

    def enable_function(self, req):
        req.decode(EMPTY)
        if not self.mon.function:
            raise PusFailure(FAILURE_REFUSED, "the parameter monitoring function is disabled")
        req.start()
        self.function = True
        self.mon.persist()

    def disable_function(self, req):
        req.decode(EMPTY)
        req.start()
        self.stop()
        self.mon.persist()

    def stop(self):
        """Disable the function: every FMON becomes unchecked."""
        self.function = False
        for f in self.fmons.values():
            f.status = FMON_UNCHECKED

    def _switch(self, req, enabled):
        ids = self._known(req.decode(FMON_IDS)["ids"])
        if not enabled:
            for i in ids:
                if self.fmons[i].protected:
                    raise _failure(FAILURE_REFUSED, "FMON %d is protected" % i, i)
        req.start()
        for i in ids:
            f = self.fmons[i]
            f.enabled = enabled
            f.status = FMON_UNCHECKED
        self.mon.persist()

    def enable(self, req):
        self._switch(req, True)

    def disable(self, req):
        self._switch(req, False)

    def _protect(self, req, protected):
        ids = self._known(req.decode(FMON_IDS)["ids"])
        req.start()
        for i in ids:
            self.fmons[i].protected = protected
        self.mon.persist()

    def protect(self, req):
        self._protect(req, True)

    def unprotect(self, req):
        self._protect(req, False)

    def add(self, req):
        items = req.decode(FMON_ADD)["items"]
        if len(self.fmons) + len(items) > self.capacity:
            raise PusFailure(FAILURE_REFUSED, "at most %d FMONs" % self.capacity)
        seen = set()
        for d in items:
            if d["fmon"] in self.fmons or d["fmon"] in seen:
                raise _failure(FAILURE_REFUSED, "FMON %d exists" % d["fmon"], d["fmon"])
            seen.add(d["fmon"])
            self._check(d)
        req.start()
        for d in items:
            self.fmons[d["fmon"]] = Fmon(d)
        self.mon.persist()

    def delete(self, req):
        ids = self._known(req.decode(FMON_IDS)["ids"])
        for i in ids:
            if self.fmons[i].enabled:
                raise _failure(FAILURE_REFUSED, "FMON %d is enabled" % i, i)
        req.start()
        for i in ids:
            del self.fmons[i]
        self.mon.persist()

    def report_definitions(self, req, message_type):
        ids = self._known(req.decode(FMON_IDS)["ids"]) or sorted(self.fmons)
        req.start()
        items = []
        for i in ids:
            f = self.fmons[i]
            d = dict(f.d)
            d["enabled"] = 1 if f.enabled else 0
            d["protected"] = 1 if f.protected else 0
            items.append(d)
        req.report(message_type, FMON_REPORT.pack({"items": items}))

    def report_status(self, req, message_type):
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
        req.report(message_type, FMON_STATUS_REPORT.pack({"items": items}))

    # -------------------------------------------------------------------------- evaluation

    def _status(self, f):
        d = f.d
        mon = self.mon
        if d["validity_mask"]:
            valid = int(mon.pool.get(d["validity"])) & d["validity_mask"] == d["validity_value"]
            if not valid:
                return FMON_INVALID
        failing = 0
        for p in d["pmons"]:
            m = mon.pmons.get(p)
            if m is not None and m.status in _FAILING:
                failing += 1
        return FMON_FAILED if failing >= d["failing"] else FMON_RUNNING

    def cyclic(self):
        """Evaluate every enabled FMON (after the PMONs of this cycle)."""
        running = self.function and self.mon.function
        for key in sorted(self.fmons):
            f = self.fmons[key]
            if not (running and f.enabled):
                f.status = FMON_UNCHECKED
                continue
            status = self._status(f)
            if status == FMON_FAILED and f.status != FMON_FAILED:
                self.failures += 1
                self._raise(f.d)
            f.status = status

    def _raise(self, d):
        event = d["event"]
        if not event:
            return
        severity = _MEDIUM
        events = self.mon.events
        if events is not None and event in events:
            severity = events[event].severity
        self.mon.raised += 1
        self.mon.app.event(event, severity, FMON_ID.pack(d["fmon"]))
