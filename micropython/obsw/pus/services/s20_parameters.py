"""ST[20] on-board parameter management: report and set parameter values, and parameter
definitions.

Values are deduced fields: each one's type is the parameter's raw type, looked up by its ID in
the spacecraft database. A report request naming an unknown parameter fails to start (the ID
in the failure data); in a set request the values cannot even be delimited without their
types, so an unknown ID fails acceptance. A set is checked whole before anything changes: a
read-only parameter is refused (``FAILURE_REFUSED``), a value whose engineering value is
outside the parameter's ``range`` fails the start with ``FAILURE_OUT_OF_RANGE`` (parameter ID
in the data) and no value changes. Sets go through the parameter pool to the components,
asynchronously; a component's refusal fails the completion.

Parameter definitions (TC[20,4] to TM[20,7]) say where a parameter's value lives. By default
it is the component attribute the database names (definition kind 0). TC[20,4] redefines
parameters as raw memory (memory ID and absolute address), TC[20,5] as object memory (memory
ID, object ID and offset in the object; object 0 is the whole area), in the memory areas and
objects service 6 serves; the value is then the parameter's raw type encoded at that place,
and every reader of the parameter pool (service 20, housekeeping, monitoring) reads it there.
A definition naming an unknown parameter, memory or object fails the start with
``FAILURE_UNKNOWN_ID``; one that does not fit in its area or object with
``FAILURE_OUT_OF_BOUNDS`` (memory ID and address, or memory ID, object ID and offset, in the
data); a parameter of variable size is refused. Definitions persist in the context store.
"""

from obsw.il.errors import CallTimeoutError, InteractionError, UnavailableError
from obsw.pus.fields import field
from obsw.pus.messages import (
    SERVICE_PARAMETER_MANAGEMENT,
    TC_PARAM_CHANGE_OBJECT_MEMORY_DEFINITIONS,
    TC_PARAM_CHANGE_RAW_MEMORY_DEFINITIONS,
    TC_PARAM_REPORT_DEFINITIONS,
    TC_PARAM_REPORT_VALUES,
    TC_PARAM_SET_VALUES,
    TM_PARAM_DEFINITION_REPORT,
    TM_PARAM_VALUE_REPORT,
)
from obsw.pus.parameters import ParameterError
from obsw.pus.services.base import (
    E8,
    PARAMETER_COUNT,
    PARAMETER_ID,
    U16,
    U32,
    Service,
    ServiceUser,
)
from obsw.pus.services.s01_verification import (
    FAILURE_COMPONENT,
    FAILURE_EXECUTION,
    FAILURE_OUT_OF_BOUNDS,
    FAILURE_OUT_OF_RANGE,
    FAILURE_REFUSED,
    FAILURE_TIMEOUT,
    FAILURE_UNAVAILABLE,
    FAILURE_UNKNOWN_ID,
    PusFailure,
)
from obsw.pus.structure import Repeated, Structure

IDS = Structure([("ids", Repeated(PARAMETER_COUNT, PARAMETER_ID))])

# definition kinds in TM[20,7] (a mission choice: the standard reports either kind)
DEFINITION_COMPONENT = 0  # the component attribute of the database
DEFINITION_RAW_MEMORY = 1  # memory ID and absolute address
DEFINITION_OBJECT_MEMORY = 2  # memory ID, object ID and offset in the object
DEFINITION_NAMES = {0: "component", 1: "raw memory", 2: "object memory"}

MEMORY_ID = U16  # as service 6 has them
OBJECT_ID = U16
ADDRESS = U32
DEFINITION_KIND = E8
RAW_DEFINITIONS = Structure(
    [
        (
            "items",
            Repeated(
                PARAMETER_COUNT,
                [("id", PARAMETER_ID), ("memory", MEMORY_ID), ("address", ADDRESS)],
            ),
        )
    ]
)
OBJECT_DEFINITIONS = Structure(
    [
        (
            "items",
            Repeated(
                PARAMETER_COUNT,
                [
                    ("id", PARAMETER_ID),
                    ("memory", MEMORY_ID),
                    ("object", OBJECT_ID),
                    ("offset", ADDRESS),
                ],
            ),
        )
    ]
)
DEFINITION_REPORT = Structure(
    [
        (
            "items",
            Repeated(
                PARAMETER_COUNT,
                [
                    ("id", PARAMETER_ID),
                    ("kind", DEFINITION_KIND),
                    ("memory", MEMORY_ID),
                    ("object", OBJECT_ID),
                    ("address", ADDRESS),
                ],
            ),
        )
    ]
)


class RangeError(ValueError):
    """A value outside its parameter's range, refused before it is sent."""


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


class _InMemory:
    """A parameter's value encoded at ``offset`` of a memory area (service 6's)."""

    def __init__(self, area, offset, ftype):
        self.area = area
        self.offset = offset
        self.ftype = ftype

    def get(self):
        return self.ftype.unpack(self.area.read(self.offset, self.ftype.bits >> 3))

    def set(self, value):
        if not self.area.writable:
            raise ValueError("the memory area is read-only")
        self.area.write(self.offset, self.ftype.pack(value))


class ParameterManagement(Service):
    """The service 20 provider, on a ``ParameterPool``; ``memories`` are service 6's memory
    areas by ID (objects with ``start``, ``size``, ``writable``, ``read``, ``write``)."""

    SERVICE = SERVICE_PARAMETER_MANAGEMENT
    NAME = "s20"
    REPORTS = (TM_PARAM_VALUE_REPORT, TM_PARAM_DEFINITION_REPORT)
    HANDLERS = (
        (TC_PARAM_REPORT_VALUES, "report_values"),
        (TC_PARAM_SET_VALUES, "set_values"),
        (TC_PARAM_CHANGE_RAW_MEMORY_DEFINITIONS, "change_raw_definitions"),
        (TC_PARAM_CHANGE_OBJECT_MEMORY_DEFINITIONS, "change_object_definitions"),
        (TC_PARAM_REPORT_DEFINITIONS, "report_definitions"),
    )

    def __init__(self, pool, memories=None):
        super().__init__()
        self.pool = pool
        self.memories = memories or {}
        self.layout = values_layout(self._type)
        self.definitions = {}  # pid -> (kind, memory ID, absolute address)
        self._pending = []  # saved definitions whose memory area is not served yet

    def _type(self, pid):
        try:
            return self.pool.type_of(pid)
        except KeyError:
            return None  # the deduced field reports an unknown selector

    def _known(self, pid):
        if pid not in self.pool:
            raise PusFailure(FAILURE_UNKNOWN_ID, "no parameter %d" % pid, PARAMETER_ID.pack(pid))
        return self.pool.parameter(pid)

    def report_values(self, req):
        ids = req.decode(IDS)["ids"]
        for pid in ids:
            self._known(pid)
        req.start()
        get = self.pool.get
        items = [{"id": pid, "value": get(pid)} for pid in ids]
        try:
            data = self.layout.pack({"items": items})
        except ValueError as e:
            raise self._unreadable(items, e) from None
        req.report(TM_PARAM_VALUE_REPORT, data)

    def _unreadable(self, items, error):
        """The failure naming the first value its parameter's type cannot carry, and why
        (the failure data: the parameter ID, then the reason as UTF-8 text)."""
        for i in items:
            p = self.pool.parameter(i["id"])
            try:
                p.type.check(i["value"])
            except ValueError as e:
                why = "%r: %s" % (i["value"], e)
                data = PARAMETER_ID.pack(p.id) + why.encode()[:200]
                return PusFailure(FAILURE_EXECUTION, "%s = %s" % (p.qualified, why), data)
        return PusFailure(FAILURE_EXECUTION, str(error))

    async def set_values(self, req):
        items = req.decode(self.layout)["items"]
        for i in items:
            p = self.pool.parameter(i["id"])
            if not p.writable:
                raise PusFailure(
                    FAILURE_REFUSED, "%s is read-only" % p.qualified, PARAMETER_ID.pack(p.id)
                )
            why = p.out_of_range(i["value"])
            if why is not None:
                raise PusFailure(
                    FAILURE_OUT_OF_RANGE, "%s: %s" % (p.qualified, why), PARAMETER_ID.pack(p.id)
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

    # -------------------------------------------------------------------------- definitions

    def _locate(self, pid, kind, memory, obj, where):
        """(parameter, area, offset in the area) of a checked definition: ``where`` is an
        absolute address (raw memory) or an offset in object ``obj`` (object memory)."""
        p = self._known(pid)
        area = self.memories.get(memory)
        if area is None:
            raise PusFailure(FAILURE_UNKNOWN_ID, "no memory %d" % memory, MEMORY_ID.pack(memory))
        bits = p.type.bits
        if bits is None or bits % 8:
            raise PusFailure(
                FAILURE_REFUSED,
                "%s has no fixed octet size to place in memory" % p.qualified,
                PARAMETER_ID.pack(pid),
            )
        n = bits >> 3
        if kind == DEFINITION_RAW_MEMORY:
            if where < area.start or where + n > area.start + area.size:
                raise PusFailure(
                    FAILURE_OUT_OF_BOUNDS,
                    "%s at %d does not fit in memory %d" % (p.qualified, where, memory),
                    MEMORY_ID.pack(memory) + ADDRESS.pack(where),
                )
            return p, area, where - area.start
        base, size = 0, area.size
        if obj:
            o = getattr(area, "objects", {}).get(obj)
            if o is None:
                raise PusFailure(
                    FAILURE_UNKNOWN_ID,
                    "memory %d has no object %d" % (memory, obj),
                    MEMORY_ID.pack(memory) + OBJECT_ID.pack(obj),
                )
            base, size = o[1], o[2]
        if where + n > size:
            raise PusFailure(
                FAILURE_OUT_OF_BOUNDS,
                "%s at %d does not fit in object %d of memory %d"
                % (p.qualified, where, obj, memory),
                MEMORY_ID.pack(memory) + OBJECT_ID.pack(obj) + ADDRESS.pack(where),
            )
        return p, area, base + where

    def _change(self, req, layout, kind):
        items = req.decode(layout)["items"]
        placed = []
        for i in items:
            if kind == DEFINITION_RAW_MEMORY:
                d = (i["id"], kind, i["memory"], 0, i["address"])
            else:
                d = (i["id"], kind, i["memory"], i["object"], i["offset"])
            self._locate(*d)
            placed.append(d)
        req.start()
        for d in placed:
            self._place(*d)
        self.persist()

    def _place(self, pid, kind, memory, obj, where):
        p, area, offset = self._locate(pid, kind, memory, obj, where)
        cell = _InMemory(area, offset, p.type)
        self.pool.provide(pid, cell.get, cell.set)
        self.definitions[pid] = (kind, memory, obj, where)

    def change_raw_definitions(self, req):
        self._change(req, RAW_DEFINITIONS, DEFINITION_RAW_MEMORY)

    def change_object_definitions(self, req):
        self._change(req, OBJECT_DEFINITIONS, DEFINITION_OBJECT_MEMORY)

    def report_definitions(self, req):
        ids = req.decode(IDS)["ids"] or sorted(self.pool.sdb.parameters)
        if len(ids) > 255:  # N is one octet: a database this large is reported by name
            raise PusFailure(FAILURE_REFUSED, "%d parameters: name at most 255" % len(ids))
        for pid in ids:
            self._known(pid)
        req.start()
        items = []
        for pid in ids:
            kind, memory, obj, where = self.definitions.get(pid, (DEFINITION_COMPONENT, 0, 0, 0))
            row = {"id": pid, "kind": kind, "memory": memory, "object": obj, "address": where}
            items.append(row)
        req.report(TM_PARAM_DEFINITION_REPORT, DEFINITION_REPORT.pack({"items": items}))

    def use_memories(self, areas):
        """Serve memory areas ``areas`` (service 6's, by ID) too, and the saved definitions
        that place parameters in them."""
        self.memories.update(areas)
        self._apply_pending()

    def _apply_pending(self):
        left = []
        for d in self._pending:
            if d[2] not in self.memories:
                left.append(d)
                continue
            try:
                self._place(*d)
            except PusFailure:  # the database changed under a saved definition: drop it
                if self.app is not None:
                    self.app.count("context_rejected")
        self._pending = left

    def context(self):
        defs = [[pid] + list(d) for pid, d in sorted(self.definitions.items())]
        return {"definitions": defs + [list(p) for p in self._pending]}

    def restore(self, ctx):
        self._pending = [tuple(d) for d in ctx["definitions"]]
        self._apply_pending()


class ParameterUser(ServiceUser):
    """The service 20 user; ``types(pid)`` and ``names(pid)`` come from the database and
    ``ids(name)`` turns a qualified name into an ID. With ``parameter(key)`` (the database's
    Parameter by ID or name), ``set`` takes engineering values (labels, calibrated numbers),
    converts them to raw and refuses a value outside the parameter's range before sending
    (``RangeError``); ``raw=True`` takes raw values, still range-checked."""

    SERVICE = SERVICE_PARAMETER_MANAGEMENT
    DECODERS = (
        (TM_PARAM_VALUE_REPORT, "decode_values"),
        (TM_PARAM_DEFINITION_REPORT, "decode_definitions"),
    )

    def __init__(self, types, names=None, ids=None, parameter=None):
        super().__init__()
        self.names = names
        self.ids = ids
        self.parameter = parameter
        self.layout = values_layout(types)

    def _id(self, key):
        return key if isinstance(key, int) or self.ids is None else self.ids(key)

    def report(self, apid, keys):
        data = IDS.pack({"ids": [self._id(k) for k in keys]})
        return self.request(apid, TC_PARAM_REPORT_VALUES, data, TM_PARAM_VALUE_REPORT)

    def raw_items(self, values, raw=False):
        """[{id, value}] of ``values`` (IDs or names to values), raw and range-checked."""
        items = []
        for k, v in values.items():
            if self.parameter is not None:
                p = self.parameter(k)
                if not raw:
                    v = p.to_raw(v)
                why = p.out_of_range(v)
                if why is not None:
                    raise RangeError("%s: %s" % (p.qualified, why))
            items.append({"id": self._id(k), "value": v})
        return items

    def set(self, apid, values, raw=False):
        """``values`` maps parameter IDs or names to new values."""
        data = self.layout.pack({"items": self.raw_items(values, raw)})
        return self.request(apid, TC_PARAM_SET_VALUES, data)

    def change_raw_definitions(self, apid, items):
        """TC[20,4]: ``items`` are (parameter, memory ID, absolute address)."""
        rows = [{"id": self._id(k), "memory": m, "address": a} for k, m, a in items]
        data = RAW_DEFINITIONS.pack({"items": rows})
        return self.request(apid, TC_PARAM_CHANGE_RAW_MEMORY_DEFINITIONS, data)

    def change_object_definitions(self, apid, items):
        """TC[20,5]: ``items`` are (parameter, memory ID, object ID, offset in the object;
        object 0: the whole area)."""
        rows = [{"id": self._id(k), "memory": m, "object": o, "offset": a} for k, m, o, a in items]
        data = OBJECT_DEFINITIONS.pack({"items": rows})
        return self.request(apid, TC_PARAM_CHANGE_OBJECT_MEMORY_DEFINITIONS, data)

    def report_definitions(self, apid, keys=()):
        """TC[20,6] (no keys: every parameter); the reply is TM[20,7]."""
        data = IDS.pack({"ids": [self._id(k) for k in keys]})
        return self.request(apid, TC_PARAM_REPORT_DEFINITIONS, data, TM_PARAM_DEFINITION_REPORT)

    def decode_values(self, tm):
        out = {}
        for i in self.layout.unpack(tm.data)["items"]:
            out[self.names(i["id"]) if self.names else i["id"]] = i["value"]
        return {"values": out}

    def decode_definitions(self, tm):
        items = DEFINITION_REPORT.unpack(tm.data)["items"]
        for i in items:
            i["kind"] = DEFINITION_NAMES.get(i["kind"], i["kind"])
            if self.names:
                i["name"] = self.names(i["id"])
        return {"definitions": items}
