"""ST[19] event-action: a TC run on board whenever a given event occurs.

A definition links an event (the APID of the process that raises it and its event ID) to a
request, a whole TC packet. When the event occurs and both the definition and the
event-action function are enabled, the request goes into the application process through
``receive``: it is checked, executed and verified like a ground TC, its reports going to its
own source ID. New definitions are disabled; an enabled one cannot be deleted or replaced.
The provider sees events by wrapping the application process's event sink, so register it
after the event reporting service (service 5); it acts on every event raised, whether or
not its report is enabled. An action raising the event that fired it is stopped after
``max_depth`` nested actions (counted as ``actions_nested``). Definitions persist in the
context store. A report request naming no definition (N = 0) reports them all.
"""

from binascii import hexlify, unhexlify

from obsw.pus.fields import field
from obsw.pus.messages import (
    SERVICE_EVENT_ACTION,
    TC_EVENT_ACTION_ADD,
    TC_EVENT_ACTION_DELETE,
    TC_EVENT_ACTION_DELETE_ALL,
    TC_EVENT_ACTION_DISABLE,
    TC_EVENT_ACTION_DISABLE_FUNCTION,
    TC_EVENT_ACTION_ENABLE,
    TC_EVENT_ACTION_ENABLE_FUNCTION,
    TC_EVENT_ACTION_REPORT_DEFINITIONS,
    TC_EVENT_ACTION_REPORT_STATUS,
    TM_EVENT_ACTION_DEFINITIONS_REPORT,
    TM_EVENT_ACTION_STATUS_REPORT,
)
from obsw.pus.packets import PusError
from obsw.pus.services.base import APID_FIELD, E8, EVENT_ID, U8, Service, ServiceUser
from obsw.pus.services.s01_verification import (
    FAILURE_REFUSED,
    FAILURE_UNKNOWN_ID,
    PusFailure,
    app_data_error,
)
from obsw.pus.services.schedule_user import describe_request, embed, request_bytes
from obsw.pus.structure import Repeated, Structure
from obsw.pus.tc import PusTc

DEFINITION_COUNT = U8  # N of a service 19 request or report
STATUS = E8  # 1 enabled, 0 disabled
REQUEST = field(12, 0)
_KEY = [("apid", APID_FIELD), ("event", EVENT_ID)]

EMPTY = Structure([])
ADD = Structure([("items", Repeated(DEFINITION_COUNT, _KEY + [("request", REQUEST)]))])
KEYS = Structure([("items", Repeated(DEFINITION_COUNT, _KEY))])
STATUS_REPORT = Structure([("items", Repeated(DEFINITION_COUNT, _KEY + [("enabled", STATUS)]))])
DEFINITIONS_REPORT = Structure(
    [
        (
            "items",
            Repeated(DEFINITION_COUNT, _KEY + [("enabled", STATUS), ("request", REQUEST)]),
        )
    ]
)
_ONE = Structure(_KEY)

_DECODE_ERRORS = (ValueError, KeyError, IndexError, TypeError)


def _key_data(key):
    return _ONE.pack({"apid": key[0], "event": key[1]})


class EventAction(Service):
    """The service 19 provider (see the module text).

    ``known`` are the event IDs of this process (the database's); definitions for its own
    APID must name one of them. ``route(raw)`` takes actions for APIDs this process does
    not serve; without it they are refused.
    """

    SERVICE = SERVICE_EVENT_ACTION
    REPORTS = (TM_EVENT_ACTION_STATUS_REPORT, TM_EVENT_ACTION_DEFINITIONS_REPORT)
    NAME = "s19"
    HANDLERS = (
        (TC_EVENT_ACTION_ADD, "add"),
        (TC_EVENT_ACTION_DELETE, "delete"),
        (TC_EVENT_ACTION_DELETE_ALL, "delete_all"),
        (TC_EVENT_ACTION_ENABLE, "enable"),
        (TC_EVENT_ACTION_DISABLE, "disable"),
        (TC_EVENT_ACTION_REPORT_STATUS, "report_status"),
        (TC_EVENT_ACTION_ENABLE_FUNCTION, "enable_function"),
        (TC_EVENT_ACTION_DISABLE_FUNCTION, "disable_function"),
        (TC_EVENT_ACTION_REPORT_DEFINITIONS, "report_definitions"),
    )

    def __init__(self, known=None, capacity=32, route=None, max_depth=4):
        super().__init__()
        self.known = set(known) if known is not None else None
        self.capacity = capacity
        self.route = route
        self.max_depth = max_depth
        self.definitions = {}  # (apid, event ID) -> [enabled, request bytes]
        self.function = True
        self.fired = 0
        self._depth = 0

    def attach(self, app):
        super().attach(app)
        app.event_listeners.append(self.on_event)

    # -------------------------------------------------------------------------- context

    def context(self):
        return {
            "function": self.function,
            "definitions": [
                [k[0], k[1], d[0], hexlify(d[1]).decode()] for k, d in self.definitions.items()
            ],
        }

    def restore(self, ctx):
        defs = {}
        for apid, event, enabled, text in ctx["definitions"]:
            raw = unhexlify(text)
            PusTc.unpack(raw)  # a damaged request rejects the whole context
            defs[(int(apid), int(event))] = [bool(enabled), raw]
        self.function = bool(ctx["function"])
        self.definitions = defs

    # -------------------------------------------------------------------------- events

    def on_event(self, event_id, severity, aux=b""):
        """The application process's event listener: run the event's action, if any."""
        self.trigger(self.app.apid, event_id)

    def trigger(self, apid, event_id):
        """Run the action of event ``event_id`` of process ``apid``; True if one ran."""
        d = self.definitions.get((apid, event_id))
        if d is None or not d[0] or not self.function:
            return False
        if self._depth >= self.max_depth:
            self.app.count("actions_nested")
            return False
        self._depth += 1
        try:
            self.fired += 1
            self.app.count("actions")
            raw = d[1]
            dest = ((raw[0] & 7) << 8) | raw[1]
            if dest in self.app.apids or self.route is None:
                self.app.receive(raw)
            else:
                self.route(raw)
        finally:
            self._depth -= 1
        return True

    # -------------------------------------------------------------------------- handlers

    def _known(self, items):
        keys = []
        for i in items:
            key = (i["apid"], i["event"])
            if key not in self.definitions:
                raise PusFailure(FAILURE_UNKNOWN_ID, "no definition %r" % (key,), _key_data(key))
            keys.append(key)
        return keys

    def add(self, req):
        try:
            items = ADD.unpack(req.data)["items"]
            tcs = [PusTc.unpack(i["request"], self.app.config) for i in items]
        except PusError as e:
            raise app_data_error("request: %s" % e) from None
        except _DECODE_ERRORS as e:
            raise app_data_error(e) from None
        req.accept()
        if len(self.definitions) + len(items) > self.capacity:
            raise PusFailure(FAILURE_REFUSED, "at most %d definitions" % self.capacity)
        seen = set()
        for i, tc in zip(items, tcs):
            key = (i["apid"], i["event"])
            data = _key_data(key)
            if key in seen or key in self.definitions:
                raise PusFailure(FAILURE_REFUSED, "definition %r exists" % (key,), data)
            seen.add(key)
            if self.known is not None and key[0] == self.app.apid and key[1] not in self.known:
                raise PusFailure(FAILURE_UNKNOWN_ID, "no event %d" % key[1], data)
            if tc.apid not in self.app.apids and self.route is None:
                raise PusFailure(FAILURE_UNKNOWN_ID, "no process %d" % tc.apid, data)
        req.start()
        for i in items:
            self.definitions[(i["apid"], i["event"])] = [False, bytes(i["request"])]
        self.persist()

    def delete(self, req):
        keys = self._known(req.decode(KEYS)["items"])
        for k in keys:
            if self.definitions[k][0]:
                raise PusFailure(FAILURE_REFUSED, "definition %r is enabled" % (k,), _key_data(k))
        req.start()
        for k in keys:
            del self.definitions[k]
        self.persist()

    def delete_all(self, req):
        req.decode(EMPTY)
        req.start()
        self.definitions = {}
        self.persist()

    def _switch(self, req, enabled):
        keys = self._known(req.decode(KEYS)["items"])
        req.start()
        for k in keys:
            self.definitions[k][0] = enabled
        self.persist()

    def enable(self, req):
        self._switch(req, True)

    def disable(self, req):
        self._switch(req, False)

    def report_status(self, req):
        req.decode(EMPTY)
        items = [
            {"apid": k[0], "event": k[1], "enabled": 1 if d[0] else 0}
            for k, d in sorted(self.definitions.items())
        ]
        req.report(TM_EVENT_ACTION_STATUS_REPORT, STATUS_REPORT.pack({"items": items}))

    def _function(self, req, enabled):
        req.decode(EMPTY)
        req.start()
        self.function = enabled
        self.persist()

    def enable_function(self, req):
        self._function(req, True)

    def disable_function(self, req):
        self._function(req, False)

    def report_definitions(self, req):
        keys = self._known(req.decode(KEYS)["items"]) or sorted(self.definitions)
        items = []
        for k in keys:
            d = self.definitions[k]
            items.append(
                {"apid": k[0], "event": k[1], "enabled": 1 if d[0] else 0, "request": d[1]}
            )
        req.report(TM_EVENT_ACTION_DEFINITIONS_REPORT, DEFINITIONS_REPORT.pack({"items": items}))


class EventActionUser(ServiceUser):
    """The service 19 user; a definition is named by ``(apid, event ID)``."""

    SERVICE = SERVICE_EVENT_ACTION
    DECODERS = (
        (TM_EVENT_ACTION_STATUS_REPORT, "decode_status"),
        (TM_EVENT_ACTION_DEFINITIONS_REPORT, "decode_definitions"),
    )

    def embed(self, apid, service, subtype, data=b"", ack=None, expect=None):
        """A TC to run as an action (see ``obsw.pus.services.schedule_user.embed``)."""
        if ack is None:
            return embed(self.proc, apid, service, subtype, data, expect=expect)
        return embed(self.proc, apid, service, subtype, data, ack, expect)

    def _keys(self, keys):
        return KEYS.pack({"items": [{"apid": k[0], "event": k[1]} for k in keys]})

    def add(self, apid, definitions):
        """``definitions``: (event APID, event ID, request) each; a request is TC bytes, a
        PusTc or the transaction of ``embed``."""
        items = [
            {"apid": d[0], "event": d[1], "request": request_bytes(d[2])} for d in definitions
        ]
        return self.request(apid, TC_EVENT_ACTION_ADD, ADD.pack({"items": items}))

    def delete(self, apid, keys):
        return self.request(apid, TC_EVENT_ACTION_DELETE, self._keys(keys))

    def delete_all(self, apid):
        return self.request(apid, TC_EVENT_ACTION_DELETE_ALL)

    def enable(self, apid, keys):
        return self.request(apid, TC_EVENT_ACTION_ENABLE, self._keys(keys))

    def disable(self, apid, keys):
        return self.request(apid, TC_EVENT_ACTION_DISABLE, self._keys(keys))

    def report_status(self, apid):
        return self.request(
            apid, TC_EVENT_ACTION_REPORT_STATUS, b"", TM_EVENT_ACTION_STATUS_REPORT
        )

    def enable_function(self, apid):
        return self.request(apid, TC_EVENT_ACTION_ENABLE_FUNCTION)

    def disable_function(self, apid):
        return self.request(apid, TC_EVENT_ACTION_DISABLE_FUNCTION)

    def report_definitions(self, apid, keys=()):
        return self.request(
            apid,
            TC_EVENT_ACTION_REPORT_DEFINITIONS,
            self._keys(keys),
            TM_EVENT_ACTION_DEFINITIONS_REPORT,
        )

    def decode_status(self, tm):
        items = STATUS_REPORT.unpack(tm.data)["items"]
        for i in items:
            i["enabled"] = bool(i["enabled"])
        return {"items": items}

    def decode_definitions(self, tm):
        out = []
        for i in DEFINITIONS_REPORT.unpack(tm.data)["items"]:
            d = describe_request(i["request"], self.proc.config if self.proc else None)
            d["event_apid"] = i["apid"]
            d["event"] = i["event"]
            d["enabled"] = bool(i["enabled"])
            out.append(d)
        return {"items": out}
