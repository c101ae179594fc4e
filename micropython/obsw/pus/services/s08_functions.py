"""ST[08] function management: perform a function, by its ID, with arguments.

The spacecraft database's ``functions`` table maps each function ID to an operation of a
component of the interaction layer ("SolarPanel.set_angle") and each argument ID to one of
its parameters, in order, with a type:

    "functions": [
      {"id": 1, "name": "SolarPanel.deploy"},
      {"id": 2, "name": "SolarPanel.set_angle",
       "arguments": [{"id": 1, "name": "angle", "type": "float32"}]}
    ]

TC[8,1] carries the function ID, N and N (argument ID, value) pairs, each value of its
argument's type. An unknown function or argument, a missing or repeated argument fail the
acceptance (the values cannot be delimited otherwise). The operation is called through the
node; an asynchronous one reports progress step 1 when it has started and completes when
it finishes. The component's refusal, its absence or a timeout fail the completion with the
function ID in the failure data; a refusal (``ComponentError``) adds what the component said,
as CBOR ``[code, message, data]``. Functions of no component (the process's own) are plain
callables given to ``local``.
"""

from obsw import cbor
from obsw.errors import UnknownNameError
from obsw.il.errors import CallTimeoutError, ComponentError, InteractionError, UnavailableError
from obsw.pus.fields import field
from obsw.pus.messages import SERVICE_FUNCTION_MANAGEMENT, TC_FUNCTION_PERFORM
from obsw.pus.sdb import SdbError, field_type
from obsw.pus.services.base import E16, U8, Service, ServiceUser
from obsw.pus.services.s01_verification import (
    FAILURE_COMPONENT,
    FAILURE_ILLEGAL_APP_DATA,
    FAILURE_TIMEOUT,
    FAILURE_UNAVAILABLE,
    FAILURE_UNKNOWN_ID,
    PusFailure,
    app_data_error,
)
from obsw.pus.structure import Repeated, Structure

FUNCTION_ID = E16
ARGUMENT_COUNT = U8
ARGUMENT_ID = U8
_HEAD = Structure([("function", FUNCTION_ID)])

_DECODE_ERRORS = (ValueError, KeyError, IndexError, TypeError)


class Function:
    """A function of the database: its ID, the operation it calls, its arguments."""

    def __init__(self, id, name, arguments=()):
        self.id = id
        self.name = name
        self.arguments = []  # (id, name, type, default) in call order
        self.by_id = {}
        for a in arguments:
            aid = a["id"]
            if not isinstance(aid, int) or not 0 <= aid <= 255 or aid in self.by_id:
                raise SdbError("function %s: argument id %r unusable or repeated" % (name, aid))
            entry = (aid, a["name"], field_type(a["type"], "%s.%s" % (name, a["name"])))
            entry += (a.get("default"),)
            self.arguments.append(entry)
            self.by_id[aid] = entry
        self.layout = Structure(
            [("function", FUNCTION_ID), ("args", Repeated(ARGUMENT_COUNT, self._arg_fields()))]
        )

    def _arg_fields(self):
        return [("id", ARGUMENT_ID), ("value", field(11, 0, key="id", lookup=self._type))]

    def _type(self, aid):
        return self.by_id[aid][2]

    def argument(self, key):
        """The argument entry with this ID or name."""
        for a in self.arguments:
            if a[0] == key or a[1] == key:
                return a
        raise KeyError("function %s has no argument %r" % (self.name, key))

    def __repr__(self):
        return "Function(%d, %s, %d arguments)" % (self.id, self.name, len(self.arguments))


def functions(sdb):
    """The database's functions by ID, as Functions (from its typed ``functions``)."""
    table = {}
    for fid, fd in sdb.functions.items():
        args = [{"id": a[0], "name": a[1], "type": a[2], "default": a[3]} for a in fd.arguments]
        table[fid] = Function(fid, fd.name, args)
    return table


def component_error_record(error):
    """What a component said when it refused (``ComponentError``), as CBOR
    ``[code, message, data]`` for the failure data after the function ID."""
    try:
        return cbor.dumps([error.code, error.message, error.data])
    except (TypeError, ValueError):  # data CBOR cannot carry: the code and the text still go
        return cbor.dumps([str(error.code), str(error.message), None])


def _failure(error, data):
    if isinstance(error, CallTimeoutError):
        return PusFailure(FAILURE_TIMEOUT, error.message, data)
    if isinstance(error, UnavailableError):
        return PusFailure(FAILURE_UNAVAILABLE, error.message, data)
    if isinstance(error, ComponentError):
        data = data + component_error_record(error)
    return PusFailure(FAILURE_COMPONENT, str(error), data)


class FunctionManagement(Service):
    """The service 8 provider: ``table`` maps function IDs to Functions (``functions``),
    ``node`` is the interaction layer node, ``local`` maps function IDs to callables."""

    SERVICE = SERVICE_FUNCTION_MANAGEMENT
    HANDLERS = ((TC_FUNCTION_PERFORM, "perform"),)

    def __init__(self, table, node=None, local=None, timeout=5.0):
        super().__init__()
        self.table = table
        self.node = node
        self.local = local or {}
        self.timeout = timeout
        self.performed = 0

    def _decode(self, req):
        data = req.data
        try:
            fid = _HEAD.unpack(data, False)["function"]
        except _DECODE_ERRORS as e:
            raise app_data_error(e) from None
        fn = self.table.get(fid)
        if fn is None:
            raise PusFailure(FAILURE_UNKNOWN_ID, "no function %d" % fid, FUNCTION_ID.pack(fid))
        try:
            given = fn.layout.unpack(data)["args"]
        except _DECODE_ERRORS as e:
            raise app_data_error(e) from None
        values = {}
        for a in given:
            if a["id"] in values:
                raise PusFailure(FAILURE_ILLEGAL_APP_DATA, "argument %d twice" % a["id"])
            values[a["id"]] = a["value"]
        args = []
        for aid, name, _, default in fn.arguments:
            if aid in values:
                args.append(values[aid])
            elif default is not None:
                args.append(default)
            else:
                raise PusFailure(FAILURE_ILLEGAL_APP_DATA, "argument %s missing" % name)
        req.accept()
        return fn, args

    def perform(self, req):
        fn, args = self._decode(req)
        data = FUNCTION_ID.pack(fn.id)
        req.start()
        self.performed += 1
        call = self.local.get(fn.id)
        if call is not None:
            try:
                result = call(*args)
            except InteractionError as e:
                raise _failure(e, data) from None
            if result is not None and hasattr(result, "send"):
                return self._await_local(result, data)
            return None
        if self.node is None:
            raise PusFailure(FAILURE_UNAVAILABLE, "no interaction layer", data)
        return self._call(req, fn, args, data)

    async def _await_local(self, pending, data):
        try:
            await pending
        except InteractionError as e:
            raise _failure(e, data) from None

    async def _call(self, req, fn, args, data):
        try:
            result = await self.node.acall(fn.name, args, timeout=self.timeout)
            if getattr(result, "accepted", False) and hasattr(result, "wait"):
                req.progress(1)  # an asynchronous operation has started
                await result.wait(self.timeout)
        except InteractionError as e:
            raise _failure(e, data) from None


class FunctionUser(ServiceUser):
    """The service 8 user on the database's function ``table``; functions and arguments
    are named by ID or by name."""

    SERVICE = SERVICE_FUNCTION_MANAGEMENT

    def __init__(self, table):
        super().__init__()
        self.table = table

    def function(self, key):
        if key in self.table:
            return self.table[key]
        for f in self.table.values():
            if f.name == key:
                return f
        raise UnknownNameError("function", key, known=[f.name for f in self.table.values()])

    def pack(self, key, arguments=None):
        """The application data of TC[8,1]; ``arguments`` maps argument IDs or names to
        values."""
        fn = self.function(key)
        args = []
        for k, v in (arguments or {}).items():
            args.append({"id": fn.argument(k)[0], "value": v})
        return fn.layout.pack({"function": fn.id, "args": args})

    def perform(self, apid, key, arguments=None):
        return self.request(apid, TC_FUNCTION_PERFORM, self.pack(key, arguments))
