"""ST[05] event reporting: event reports of four severities, enable, disable, disabled list.

The provider becomes the application process's event sink: ``report(event_id, severity,
aux)`` sends TM[5,severity] unless the event is disabled. The disabled list persists in the
context store. With ``known`` (the spacecraft database's event IDs) a request naming an
unknown event fails to start, with that ID in the failure data, and nothing changes.
"""

from obsw.pus.messages import (
    SERVICE_EVENT_REPORTING,
    TC_EVENT_DISABLE,
    TC_EVENT_ENABLE,
    TC_EVENT_REPORT_DISABLED,
    TM_EVENT_DISABLED_LIST_REPORT,
    TM_EVENT_HIGH_SEVERITY,
    TM_EVENT_INFORMATIVE,
    TM_EVENT_LOW_SEVERITY,
    TM_EVENT_MEDIUM_SEVERITY,
)
from obsw.pus.services.base import EVENT_COUNT, EVENT_ID, Service, ServiceUser
from obsw.pus.services.s01_verification import FAILURE_UNKNOWN_ID, PusFailure
from obsw.pus.structure import Repeated, Structure

IDS = Structure([("ids", Repeated(EVENT_COUNT, EVENT_ID))])
EMPTY = Structure([])

SEVERITY_NAMES = {1: "info", 2: "low", 3: "medium", 4: "high"}


class EventReporting(Service):
    """The service 5 provider (see the module text)."""

    SERVICE = SERVICE_EVENT_REPORTING
    REPORTS = (
        TM_EVENT_INFORMATIVE,
        TM_EVENT_LOW_SEVERITY,
        TM_EVENT_MEDIUM_SEVERITY,
        TM_EVENT_HIGH_SEVERITY,
        TM_EVENT_DISABLED_LIST_REPORT,
    )
    NAME = "s05"
    HANDLERS = (
        (TC_EVENT_ENABLE, "enable"),
        (TC_EVENT_DISABLE, "disable"),
        (TC_EVENT_REPORT_DISABLED, "report_disabled"),
    )

    def __init__(self, known=None):
        super().__init__()
        self.known = set(known) if known is not None else None
        self.disabled = set()
        self.reported = 0
        self.suppressed = 0

    def attach(self, app):
        super().attach(app)
        app.event_reporters.append(self.report)

    def context(self):
        return sorted(self.disabled)

    def restore(self, ctx):
        self.disabled = set(int(i) for i in ctx)

    def report(self, event_id, severity, aux=b""):
        """Send the event report unless the event is disabled; True if it went out."""
        if event_id in self.disabled:
            self.suppressed += 1
            return False
        if not 1 <= severity <= 4:
            severity = 4  # a severity out of range is reported as high rather than lost
        self.reported += 1
        return self.app.send_tm(5, severity, EVENT_ID.pack(event_id) + bytes(aux)) is not None

    def _ids(self, req):
        ids = req.decode(IDS)["ids"]
        if self.known is not None:
            for i in ids:
                if i not in self.known:
                    raise PusFailure(FAILURE_UNKNOWN_ID, "no event %d" % i, EVENT_ID.pack(i))
        req.start()
        return ids

    def enable(self, req):
        for i in self._ids(req):
            self.disabled.discard(i)
        self.persist()

    def disable(self, req):
        for i in self._ids(req):
            self.disabled.add(i)
        self.persist()

    def report_disabled(self, req):
        req.decode(EMPTY)
        req.report(TM_EVENT_DISABLED_LIST_REPORT, IDS.pack({"ids": sorted(self.disabled)}))


class EventUser(ServiceUser):
    """The service 5 user; ``lookup(event_id)`` gives the database's EventDef (or raises
    KeyError), used to name events and decode their auxiliary data."""

    SERVICE = SERVICE_EVENT_REPORTING
    DECODERS = (
        (TM_EVENT_INFORMATIVE, "decode_event"),
        (TM_EVENT_LOW_SEVERITY, "decode_event"),
        (TM_EVENT_MEDIUM_SEVERITY, "decode_event"),
        (TM_EVENT_HIGH_SEVERITY, "decode_event"),
        (TM_EVENT_DISABLED_LIST_REPORT, "decode_disabled"),
    )

    def __init__(self, lookup=None):
        super().__init__()
        self.lookup = lookup

    def enable(self, apid, ids):
        return self.request(apid, TC_EVENT_ENABLE, IDS.pack({"ids": list(ids)}))

    def disable(self, apid, ids):
        return self.request(apid, TC_EVENT_DISABLE, IDS.pack({"ids": list(ids)}))

    def report_disabled(self, apid):
        return self.request(apid, TC_EVENT_REPORT_DISABLED, b"", TM_EVENT_DISABLED_LIST_REPORT)

    def decode_event(self, tm):
        data = tm.data
        event_id = EVENT_ID.unpack(data)
        aux = bytes(data[2:])
        out = {"id": event_id, "severity": SEVERITY_NAMES[tm.subtype]}
        ev = None
        if self.lookup is not None:
            try:
                ev = self.lookup(event_id)
            except KeyError:
                ev = None
        if ev is None:
            out["data"] = aux
        else:
            out["event"] = ev.qualified
            out["data"] = ev.unpack(aux)
            if getattr(ev, "labels", None):  # for display: labelled fields as their labels
                out["labelled"] = ev.labelled(out["data"])
        return out

    def decode_disabled(self, tm):
        return IDS.unpack(tm.data)
