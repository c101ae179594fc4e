"""ST[20] on-board parameter management: report and set parameter values.

Values are deduced fields: each one's type is the parameter's, looked up by its ID in the
spacecraft database. A report request naming an unknown parameter fails to start (the ID
in the failure data); in a set request the values cannot even be delimited without their
types, so an unknown ID fails acceptance. Sets go through the parameter pool to the
components, asynchronously; a component's refusal fails the completion.
"""

from obsw.il.errors import CallTimeoutError, InteractionError, UnavailableError
from obsw.pus.fields import field
from obsw.pus.messages import (
    SERVICE_PARAMETER_MANAGEMENT,
    TC_PARAM_REPORT_VALUES,
    TC_PARAM_SET_VALUES,
    TM_PARAM_VALUE_REPORT,
)
from obsw.pus.parameters import ParameterError
from obsw.pus.services.base import PARAMETER_COUNT, PARAMETER_ID, Service, ServiceUser
from obsw.pus.services.s01_verification import (
    FAILURE_COMPONENT,
    FAILURE_REFUSED,
    FAILURE_TIMEOUT,
    FAILURE_UNAVAILABLE,
    FAILURE_UNKNOWN_ID,
    PusFailure,
)
from obsw.pus.structure import Repeated, Structure

IDS = Structure([("ids", Repeated(PARAMETER_COUNT, PARAMETER_ID))])


def values_layout(types):
    """N, then N (parameter ID, value) pairs; ``types(pid)`` gives each value's field type."""
    return Structure(
        [
            (
                "items",
                Repeated(
                    PARAMETER_COUNT,
                    [("id", PARAMETER_ID), ("value", field(11, 0, key="id", lookup=types))],
                ),
            )
        ]
    )


def _failure(error, pid):
    data = PARAMETER_ID.pack(pid)
    if isinstance(error, CallTimeoutError):
        return PusFailure(FAILURE_TIMEOUT, error.message, data)
    if isinstance(error, UnavailableError):
        return PusFailure(FAILURE_UNAVAILABLE, error.message, data)
    return PusFailure(FAILURE_COMPONENT, str(error), data)


class ParameterManagement(Service):
    """The service 20 provider, on a ``ParameterPool``."""

    SERVICE = SERVICE_PARAMETER_MANAGEMENT
    REPORTS = (TM_PARAM_VALUE_REPORT,)
    HANDLERS = (
        (TC_PARAM_REPORT_VALUES, "report_values"),
        (TC_PARAM_SET_VALUES, "set_values"),
    )

    def __init__(self, pool):
        super().__init__()
        self.pool = pool
        self.layout = values_layout(self._type)

    def _type(self, pid):
        try:
            return self.pool.type_of(pid)
        except KeyError:
            return None  # the deduced field reports an unknown selector

    def report_values(self, req):
        ids = req.decode(IDS)["ids"]
        for pid in ids:
            if pid not in self.pool:
                raise PusFailure(
                    FAILURE_UNKNOWN_ID, "no parameter %d" % pid, PARAMETER_ID.pack(pid)
                )
        req.start()
        get = self.pool.get
        req.report(
            TM_PARAM_VALUE_REPORT,
            self.layout.pack({"items": [{"id": pid, "value": get(pid)} for pid in ids]}),
        )

    async def set_values(self, req):
        items = req.decode(self.layout)["items"]
        for i in items:
            p = self.pool.parameter(i["id"])
            if not p.writable:
                raise PusFailure(
                    FAILURE_REFUSED, "%s is read-only" % p.qualified, PARAMETER_ID.pack(p.id)
                )
        req.start()
        for i in items:
            pid = i["id"]
            try:
                await self.pool.aset(pid, i["value"])
            except ParameterError as e:
                raise PusFailure(FAILURE_REFUSED, str(e), PARAMETER_ID.pack(pid)) from None
            except (InteractionError, ValueError) as e:
                raise _failure(e, pid) from None


class ParameterUser(ServiceUser):
    """The service 20 user; ``types(pid)`` and ``names(pid)`` come from the database and
    ``ids(name)`` turns a qualified name into an ID."""

    SERVICE = SERVICE_PARAMETER_MANAGEMENT
    DECODERS = ((TM_PARAM_VALUE_REPORT, "decode_values"),)

    def __init__(self, types, names=None, ids=None):
        super().__init__()
        self.names = names
        self.ids = ids
        self.layout = values_layout(types)

    def _id(self, key):
        return key if isinstance(key, int) or self.ids is None else self.ids(key)

    def report(self, apid, keys):
        data = IDS.pack({"ids": [self._id(k) for k in keys]})
        return self.request(apid, TC_PARAM_REPORT_VALUES, data, TM_PARAM_VALUE_REPORT)

    def set(self, apid, values):
        """``values`` maps parameter IDs or names to new values."""
        items = [{"id": self._id(k), "value": v} for k, v in values.items()]
        return self.request(apid, TC_PARAM_SET_VALUES, self.layout.pack({"items": items}))

    def decode_values(self, tm):
        out = {}
        for i in self.layout.unpack(tm.data)["items"]:
            out[self.names(i["id"]) if self.names else i["id"]] = i["value"]
        return {"values": out}
