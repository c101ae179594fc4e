"""Mission-specific services (types 128..255): provider and user built from a ServiceDef.

``MissionService(definition, node)`` serves every request of a service the spacecraft
database declares (``obsw.pus.sdb_services``): it decodes the TC's application data with the
request's field types (undecodable data, or data left over, fails the acceptance with
illegal application data; a value outside an argument's range fails it with "out of
range" and the argument's index as failure data), calls the request's operation of the
service's component over the interaction layer, and sends the operation's return value as
the request's report. An asynchronous operation reports progress step 1 when it has
started. The component's refusal, its absence or a timeout fail the completion (component
error, unavailable, timeout) with the request's subtype as failure data. Reports that name
an ``event`` go to ground, unsolicited, each time the component publishes it.

``MissionServiceUser(definition)`` is the ground's side: it checks arguments by name, type
and range before anything is sent, and decodes every report of the service by name.
"""

from obsw.il.errors import CallTimeoutError, InteractionError, UnavailableError
from obsw.pus.services.base import U8, Service, ServiceUser
from obsw.pus.services.s01_verification import (
    FAILURE_COMPONENT,
    FAILURE_EXECUTION,
    FAILURE_OUT_OF_RANGE,
    FAILURE_TIMEOUT,
    FAILURE_UNAVAILABLE,
    PusFailure,
    app_data_error,
)

ARGUMENT_INDEX = U8  # failure data of an argument out of range: its index, from 0
SUBTYPE = U8  # failure data of a request that failed in execution: its subtype

_DECODE_ERRORS = (ValueError, KeyError, IndexError, TypeError)


class MissionArgumentError(ValueError):
    """Arguments of a mission request that do not match its declaration (ground side)."""


def _failure(error, data):
    if isinstance(error, CallTimeoutError):
        return PusFailure(FAILURE_TIMEOUT, error.message, data)
    if isinstance(error, UnavailableError):
        return PusFailure(FAILURE_UNAVAILABLE, error.message, data)
    return PusFailure(FAILURE_COMPONENT, str(error), data)


class MissionService(Service):
    """The provider of one mission service (see the module text)."""

    def __init__(self, definition, node=None, timeout=5.0):
        super().__init__()
        self.definition = definition
        self.SERVICE = definition.type
        self.REPORTS = tuple(r.message_type for r in definition.reports.values())
        self.node = node
        self.timeout = timeout
        self.performed = 0
        self.events_reported = 0
        self.unfit_reports = 0  # replies or event payloads that did not fit their report
        self.unbound = []  # "Component.event" the (local) component does not publish
        self._subs = []

    def attach(self, app):
        super().attach(app)
        for subtype, request in self.definition.requests.items():
            self._handlers[subtype] = self._handler(request)
        self._bind()

    def _handler(self, request):
        return lambda req: self.perform(request, req)

    def _bind(self):
        if self.node is None:
            return
        for report in self.definition.reports.values():
            if report.event is None:
                continue
            topic = "%s.%s" % (self.definition.component, report.event)
            try:
                self._subs.append(self.node.watch(topic, self._published(report)))
            except InteractionError:
                self.unbound.append(topic)

    def _published(self, report):
        return lambda pub: self._event_report(report, pub.value)

    def _event_report(self, report, payload):
        try:
            data = report.pack(payload)
        except _DECODE_ERRORS:
            self.unfit_reports += 1
            return
        self.events_reported += 1
        self.send(report.message_type, data)

    def decode(self, request, req):
        """The arguments of ``req`` in call order; fails the acceptance if they do not fit."""
        try:
            values = request.layout.unpack(req.data)
        except _DECODE_ERRORS as e:
            raise app_data_error(e) from None
        args = []
        for i, f in enumerate(request.fields):
            why = f.out_of_range(values[f.name])
            if why is not None:
                raise PusFailure(FAILURE_OUT_OF_RANGE, why, ARGUMENT_INDEX.pack(i))
            args.append(values[f.name])
        req.accept()
        return args

    def perform(self, request, req):
        args = self.decode(request, req)
        data = SUBTYPE.pack(request.subtype)
        if self.node is None:  # fails the start: nothing was done
            raise PusFailure(FAILURE_UNAVAILABLE, "no interaction layer", data)
        req.start()
        self.performed += 1
        return self._call(request, req, args, data)

    async def _call(self, request, req, args, data):
        name = self.definition.operation(request)
        try:
            result = await self.node.acall(name, args, timeout=self.timeout)
            if getattr(result, "accepted", False) and hasattr(result, "wait"):
                req.progress(1)  # an asynchronous operation has started
                result = await result.wait(self.timeout)
        except InteractionError as e:
            raise _failure(e, data) from None
        if request.report is None:
            return
        report = self.definition.reports[request.report]
        try:
            out = report.pack(result)
        except _DECODE_ERRORS as e:
            self.unfit_reports += 1
            raise PusFailure(
                FAILURE_EXECUTION,
                "%s returned what %s cannot carry: %s" % (name, report.name, e),
                data,
            ) from None
        req.report(report.message_type, out)

    def close(self):
        for s in self._subs:
            s.cancel()
        self._subs = []


class MissionServiceUser(ServiceUser):
    """The ground's user of one mission service (see the module text)."""

    def __init__(self, definition):
        super().__init__()
        self.definition = definition
        self.SERVICE = definition.type

    def attach(self, proc):
        super().attach(proc)
        for subtype, report in self.definition.reports.items():
            self._decoders[subtype] = self._decoder(report)

    def _decoder(self, report):
        return lambda tm: {
            "service": self.definition.name,
            "report": report.name,
            "fields": report.unpack(tm.data),
        }

    def arguments(self, key, given):
        """``given`` ({name: value}) checked against request ``key``: the values in field
        order, or MissionArgumentError naming what is wrong."""
        request = self.definition.request(key)
        names = [f.name for f in request.fields]
        for k in given:
            if k not in names:
                raise MissionArgumentError(
                    "%s takes no argument %s; expected %s"
                    % (request.qualified, k, ", ".join(names) or "none")
                )
        out = {}
        for f in request.fields:
            if f.name not in given:
                raise MissionArgumentError("%s needs argument %s" % (request.qualified, f.name))
            try:
                value = f.type.check(given[f.name])
            except (ValueError, TypeError) as e:
                raise MissionArgumentError("%s: %s" % (request.qualified, e)) from None
            value = given[f.name] if value is None else value
            why = f.out_of_range(value)
            if why is not None:
                raise MissionArgumentError("%s: %s" % (request.qualified, why))
            out[f.name] = value
        return request, out

    def pack(self, key, given):
        """The application data of request ``key`` with arguments ``given`` (by name)."""
        request, values = self.arguments(key, given)
        return request.layout.pack(values)

    def send(self, apid, key, given):
        """Send request ``key``; the transaction's reply is its report, if it declares one."""
        request, values = self.arguments(key, given)
        expect = None if request.report is None else (self.definition.type, request.report)
        return self.request(apid, request.message_type, request.layout.pack(values), expect)
