"""The spacecraft database: the one place a mission tailors ids, types and APIDs (JSON).

    {
      "mission": "demo",
      "apids": {"pus": 10, "cfdp": 100},
      "components": [
        {"name": "SolarPanel",
         "attributes": [{"name": "angle", "parameter": 1, "type": "float32", "unit": "deg"}],
         "events": [{"name": "angle_reached", "id": 1, "severity": "info",
                     "data": [{"name": "angle", "type": "float32"}]}]}
      ],
      "events": [{"name": "pus.cycle_overrun", "id": 65281, "severity": "medium"}],
      "housekeeping": [{"sid": 1, "interval": 10, "parameters": [1], "enabled": true}],
      "filestores": [{"prefix": "SAT", "entity": 2}, {"prefix": "GROUND", "entity": 1}],
      "memories": [{"id": 1, "name": "image", "file": "memory/image.bin",
                    "start": 0, "size": 4096, "writable": true}]
    }

Also parsed here, so nothing else reads the JSON: ``functions`` (service 8: id, name, the
operation's typed arguments), components' ``operations`` (name and arguments with units, for
PLUTO's checker), ``position_scheduling`` (service 22's position parameter), ``frames``
(``tm_vcs``: the TM virtual channel plan, role -> VC ID, and ``scid``; ``tc_vc``, ``maps`` and
``cfdp_vc`` are kept in ``frames`` for the mission's ids), ``pus`` (the packet layout and the
ground's source id, read by ``obsw.pus.config.from_sdb``) and ``nodes`` (SpaceCAN equipment:
name, node id, node definition file relative to the database file) and ``services`` (the
mission's own PUS services, types 128..255: ``obsw.pus.sdb_services``).

``filestores`` maps the path prefixes of file management (``SAT:/data/x``) to CFDP entity
ids (the onboard one is the first, unless one says ``"local": true``); ``memories`` declares
the memory areas service 6 may load, dump and check, by id, start address and size, with
their ``objects`` (id, name, offset, size: the object memory of service 6) and an optional
``mirror`` file (a second copy written with the first, from which scrubbing repairs).

A type is a name (``uint8`` .. ``uint64``, ``int8`` .. ``int64``, ``float32``, ``float64``,
``bool``, ``enum8``, ``enum16``, ``string`` for a 16-bit-length character string,
``octets``) or a ``[ptc, pfc]`` pair. ``load``/``loads`` check that every id is unique.
"""

from obsw import jsonsafe
from obsw.errors import UnknownNameError
from obsw.pus.fields import field
from obsw.pus.structure import Structure

SEVERITIES = {"info": 1, "low": 2, "medium": 3, "high": 4}
SEVERITY_NAMES = {1: "info", 2: "low", 3: "medium", 4: "high"}

TYPES = {
    "bool": (1, 8),
    "enum8": (2, 8),
    "enum16": (2, 16),
    "uint8": (3, 4),
    "uint16": (3, 12),
    "uint32": (3, 14),
    "uint64": (3, 16),
    "int8": (4, 4),
    "int16": (4, 12),
    "int32": (4, 14),
    "int64": (4, 16),
    "float32": (5, 1),
    "float64": (5, 2),
    "string": (8, 0),
    "octets": (7, 0),
}


class SdbError(ValueError):
    """A spacecraft database that is malformed or gives one id to two things."""


def field_type(spec, where="type"):
    """The packet field type for a type name or a [ptc, pfc] pair."""
    if isinstance(spec, str):
        pair = TYPES.get(spec)
        if pair is None:
            raise SdbError(
                "%s: unknown type %r, expected one of %s" % (where, spec, sorted(TYPES))
            )
    elif isinstance(spec, (list, tuple)) and len(spec) == 2:
        pair = tuple(spec)
    else:
        raise SdbError("%s: type %r, expected a name or [ptc, pfc]" % (where, spec))
    try:
        return field(pair[0], pair[1])
    except ValueError as e:
        raise SdbError("%s: %s" % (where, e)) from None


class Parameter:
    """An attribute of a component as a PUS parameter. ``type`` is the raw value (what packets
    carry); ``unit`` the engineering unit, ``raw_unit`` the raw one. ``extras`` are the optional
    entries, kept as given and checked by ``obsw.pus.calibration``: ``range`` ([low, high] a set
    may use, engineering units), ``limits`` (``{"warning": [low, high], "critical": [low,
    high]}``, engineering units), ``calibration`` (``{"polynomial": [c0, c1, ..]}`` or
    ``{"spline": [[raw, eng], ..]}``), ``enumeration`` (labels of raw values),
    ``description``. ``values`` converts raw <-> engineering."""

    def __init__(
        self, id, component, name, type_spec, unit=None, writable=False, default=None, extras=None
    ):
        self.id = id
        self.component = component
        self.name = name  # the attribute name
        self.type_spec = type_spec
        self.type = field_type(type_spec, "parameter %s.%s" % (component, name))
        self.unit = unit
        self.writable = writable
        self.default = default
        extras = extras or {}
        self.range = extras.get("range")
        self.limits = extras.get("limits")
        self.calibration = extras.get("calibration")
        self.raw_unit = extras.get("raw_unit")
        self.description = extras.get("description")
        self.values = None  # obsw.pus.calibration.Values, for an entry that has any of them
        for key in _VALUE_ENTRIES:
            if extras.get(key) is not None:
                self.values = _values(self.type, extras, "parameter " + self.qualified)
                break

    @property
    def labels(self):
        """{raw value: label} of an enumeration, or None."""
        return None if self.values is None else self.values.labels

    def engineering(self, raw):
        """The engineering value of raw value ``raw`` (a label for an enumeration)."""
        return raw if self.values is None else self.values.engineering(raw)

    def to_raw(self, eng):
        """The raw value of an engineering value or label (CalibrationError if none)."""
        return eng if self.values is None else self.values.to_raw(eng)

    def out_of_range(self, raw):
        """None if raw value ``raw`` is within the parameter's range, else why not."""
        return None if self.values is None else self.values.out_of_range(raw)

    def raw_limits(self, low, high, raw=False):
        """(raw low, raw high, swapped) of a limit check from engineering limits (``raw``:
        raw limits, checked against the type); see ``obsw.pus.calibration.Values``."""
        values = self.values if self.values is not None else _values(self.type, {}, "")
        if raw:
            return values.raw_limits_of(low, high) + (False,)
        return values.raw_limits(low, high)

    @property
    def qualified(self):
        return "%s.%s" % (self.component, self.name) if self.component else self.name

    def __repr__(self):
        return "Parameter(%d, %s, %s)" % (self.id, self.qualified, self.type.name)


_VALUE_ENTRIES = ("calibration", "enumeration", "range", "limits")


def _values(ftype, extras, what):
    # imported here, not at the top: a database with no calibration, label, range or limits
    # (a small board's) does not pay the module's heap
    from obsw.pus.calibration import CalibrationError, Values

    try:
        return Values(ftype, extras, what)
    except CalibrationError as e:
        raise SdbError(str(e)) from None


class EventDef:
    """An event with its PUS event ID, severity (1..4) and auxiliary data layout."""

    def __init__(self, id, component, name, severity, data=()):
        self.id = id
        self.component = component
        self.name = name
        self.severity = severity
        self.type_specs = [(f["name"], f["type"]) for f in data]
        self.fields = [
            (f["name"], field_type(f["type"], "event %s field %s" % (name, f.get("name"))))
            for f in data
        ]
        self.layout = Structure(self.fields)
        self.labels = _labels(data, "name", "event %s" % name)  # field -> {raw: label}

    @property
    def qualified(self):
        return "%s.%s" % (self.component, self.name) if self.component else self.name

    def labelled(self, values):
        """Decoded ``values`` with each labelled field's raw value as its label."""
        if not self.labels or not isinstance(values, dict):
            return values
        out = dict(values)
        for k, labels in self.labels.items():
            if k in out:
                out[k] = labels.get(out[k], out[k])
        return out

    def pack(self, payload):
        """Auxiliary data for ``payload``: a dict, a list in field order, or a single value."""
        if not self.fields:
            return b""
        if not isinstance(payload, dict):
            if not isinstance(payload, (list, tuple)):
                payload = (payload,)
            payload = dict(zip([n for n, _ in self.fields], payload))
        return self.layout.pack(payload)

    def unpack(self, data):
        return self.layout.unpack(data) if self.fields else {}

    def __repr__(self):
        return "EventDef(%d, %s, %s)" % (self.id, self.qualified, SEVERITY_NAMES[self.severity])


def _int(value, what):
    if not isinstance(value, int) or isinstance(value, bool) or value < 0:
        raise SdbError("%s must be an integer >= 0, got %r" % (what, value))
    return value


def _severity(value, what):
    if isinstance(value, str):
        s = SEVERITIES.get(value.lower())
    else:
        s = value if value in (1, 2, 3, 4) else None
    if s is None:
        raise SdbError("%s: severity %r, expected info, low, medium or high" % (what, value))
    return s


def _labels(entries, key, what):
    """{entry[key]: {raw: label}} of the ``entries`` with an ``enumeration``, or None."""
    out = None
    for e in entries:
        spec = e.get("enumeration")
        if spec is not None:
            # imported here, as for values: a database without labels does not pay its heap
            from obsw.pus.calibration import CalibrationError, enumeration

            try:
                labels = enumeration(spec, "%s %s.enumeration" % (what, e.get(key)))
            except CalibrationError as x:
                raise SdbError(str(x)) from None
            if out is None:
                out = {}
            out[e[key]] = labels
    return out


class FunctionDef:
    """A service 8 function: ``arguments`` are (id, name, type spec, default) in call order;
    ``labels`` maps an argument id to its enumeration ({raw: label}), or is None."""

    __slots__ = ("id", "name", "arguments", "labels")

    def __init__(self, id, name, arguments, labels=None):
        self.id = id
        self.name = name
        self.arguments = arguments
        self.labels = labels

    def __repr__(self):
        return "FunctionDef(%d, %s)" % (self.id, self.name)


class OperationDef:
    """An operation of a component: ``arguments`` are (name, unit) pairs (None: not given);
    ``signature`` is its declared arguments as (name, type, unit), type None when not given,
    or None when the database lists no ``arguments`` (any arguments then)."""

    __slots__ = ("component", "name", "arguments", "signature")

    def __init__(self, component, name, arguments, signature=None):
        self.component = component
        self.name = name
        self.arguments = arguments
        self.signature = signature

    @property
    def qualified(self):
        return "%s.%s" % (self.component, self.name)


# -- operations: the activity signatures PLUTO procedures are checked against at load time


def _operation(cname, op):
    """An ``OperationDef`` from a component's ``operations`` entry: each argument is
    ``{"name": n, "type": t, "unit": u}`` (type and unit optional; a type is checked here);
    ``"arguments": []`` declares an operation that takes none."""
    where = "operation %s.%s" % (cname, op["name"])
    args = []
    sig = []
    seen = set()
    for a in op.get("arguments", ()):
        name = a["name"]
        if name in seen:
            raise SdbError("%s declares argument %s twice" % (where, name))
        seen.add(name)
        t = a.get("type")
        if t is not None:
            field_type(t, "%s, argument %s" % (where, name))
        args.append((name, a.get("unit")))
        sig.append((name, t, a.get("unit")))
    return OperationDef(cname, op["name"], args, sig if "arguments" in op else None)


class NodeDef:
    """A SpaceCAN equipment node: its component name, node id and definition file; ``role``
    is ``nominal`` or ``redundant`` for the reconfiguration module's two controllers."""

    __slots__ = ("name", "node_id", "definition", "role")

    def __init__(self, name, node_id, definition, role=None):
        self.name = name
        self.node_id = node_id
        self.definition = definition
        self.role = role

    def __repr__(self):
        return "NodeDef(%s, %d)" % (self.name, self.node_id)


class Sdb:
    """The parsed database: every section as typed objects, by id and by name."""

    def __init__(self, doc, base=""):
        if not isinstance(doc, dict):
            raise SdbError("spacecraft database must be a JSON object")
        self.mission = doc.get("mission", "")
        self.apids = {}
        self.components = []
        self.parameters = {}  # id -> Parameter
        self.events = {}  # id -> EventDef
        self.housekeeping = []  # initial report structures as dicts
        self.filestores = {}  # path prefix ('SAT') -> CFDP entity id
        self.local_filestore = None  # the prefix of the onboard filestore
        self.memories = {}  # memory id -> dict (name, file, start, size, writable)
        self.functions = {}  # function id -> FunctionDef
        self.operations = {}  # "Component.operation" -> OperationDef
        self.position_parameter = None  # service 22's position parameter (a Parameter)
        self.tm_vcs = None  # TM virtual channel plan (role -> VC ID), None: the default
        self.scid = None  # spacecraft id, when the database gives it
        self.frames = {}  # the frames plan as given (scid, tc_vc, maps, tm_vcs, cfdp_vc)
        self.pus = {}  # the PUS section as given: packet layout and source id (obsw.pus.config)
        self.nodes = {}  # SpaceCAN equipment name -> NodeDef
        self.services = {}  # mission service type (128..255) -> sdb_services.ServiceDef
        self.base = base  # the folder relative paths start from
        self._params_by_name = {}
        self._events_by_name = {}
        self._functions_by_name = {}
        unknown = [k for k in doc if k not in _KNOWN]
        if unknown:
            raise SdbError("spacecraft database: unknown section %s" % ", ".join(sorted(unknown)))
        try:
            self._load(doc)
        except (KeyError, TypeError, AttributeError) as e:
            raise SdbError("spacecraft database: missing or malformed entry (%r)" % (e,)) from None

    def _load(self, doc):
        used = {}
        for name, apid in doc.get("apids", {}).items():
            _int(apid, "APID of %s" % name)
            if apid > 0x7FF:
                raise SdbError("APID of %s is %d, above 2047" % (name, apid))
            if apid in used:
                raise SdbError("APID %d given to both %s and %s" % (apid, used[apid], name))
            used[apid] = name
            self.apids[name] = apid
        for comp in doc.get("components", []):
            cname = comp["name"]
            if cname in self.components:
                raise SdbError("component %s declared twice" % cname)
            self.components.append(cname)
            seen = set()
            for a in comp.get("attributes", []):
                if a["name"] in seen:
                    raise SdbError("%s declares attribute %s twice" % (cname, a["name"]))
                seen.add(a["name"])
                self._add_parameter(
                    Parameter(
                        _int(a["parameter"], "parameter id of %s.%s" % (cname, a["name"])),
                        cname,
                        a["name"],
                        a["type"],
                        a.get("unit"),
                        bool(a.get("writable", False)),
                        a.get("default"),
                        a,
                    )
                )
            for e in comp.get("events", []):
                self._add_event(cname, e)
            for op in comp.get("operations", []):
                self.operations["%s.%s" % (cname, op["name"])] = _operation(cname, op)
        for p in doc.get("parameters", []):  # parameters of no component (process-local)
            self._add_parameter(
                Parameter(
                    _int(p["id"], "parameter id of %s" % p["name"]),
                    None,
                    p["name"],
                    p["type"],
                    p.get("unit"),
                    bool(p.get("writable", False)),
                    p.get("default"),
                    p,
                )
            )
        for e in doc.get("events", []):
            self._add_event(None, e)
        sids = set()
        for hk in doc.get("housekeeping", []):
            sid = _int(hk["sid"], "housekeeping structure id")
            if sid in sids:
                raise SdbError("housekeeping structure %d declared twice" % sid)
            sids.add(sid)
            pids = [self.parameter(p).id for p in hk["parameters"]]
            self.housekeeping.append(
                {
                    "sid": sid,
                    "interval": _int(hk.get("interval", 1), "interval of structure %d" % sid),
                    "parameters": pids,
                    "enabled": bool(hk.get("enabled", False)),
                }
            )
        self._load_files(doc)
        self._load_functions(doc)
        self._load_spacecraft(doc)
        if doc.get("services"):
            self._load_services(doc["services"])

    def _load_services(self, items):
        # imported here, not at the top: a database with no mission service (a small
        # board's) does not pay the module's heap
        from obsw.pus.sdb_services import load_services, signatures

        self.services = load_services(items)
        for name, sig in signatures(self.services).items():
            if name not in self.operations:  # the request declares the activity's signature
                comp, op = name.split(".", 1)
                args = [(a[0], a[2]) for a in sig]
                self.operations[name] = OperationDef(comp, op, args, sig)

    def service(self, key):
        """The mission ServiceDef with this type or name."""
        s = self.services.get(key) if isinstance(key, int) else None
        if s is None:
            for candidate in self.services.values():
                if candidate.name == key:
                    s = candidate
        if s is None:
            raise UnknownNameError("mission service", key, known=_names(self.services.values()))
        return s

    def _load_functions(self, doc):
        for f in doc.get("functions", []):
            fid = f["id"]
            if not isinstance(fid, int) or not 0 <= fid <= 0xFFFF or fid in self.functions:
                raise SdbError("function id %r unusable or repeated" % (fid,))
            name = f["name"]
            if name in self._functions_by_name:
                raise SdbError("function %s declared twice" % name)
            args = []
            seen = set()
            for a in f.get("arguments", ()):
                aid = a["id"]
                if not isinstance(aid, int) or not 0 <= aid <= 255 or aid in seen:
                    raise SdbError(
                        "function %s: argument id %r unusable or repeated" % (name, aid)
                    )
                seen.add(aid)
                field_type(a["type"], "%s.%s" % (name, a["name"]))
                args.append((aid, a["name"], a["type"], a.get("default")))
            fd = FunctionDef(fid, name, args, _labels(f.get("arguments", ()), "id", name))
            self.functions[fid] = fd
            self._functions_by_name[name] = fd
            if "." in name and name not in self.operations:  # PLUTO checks its arguments
                sig = [(a["name"], a["type"], a.get("unit")) for a in f.get("arguments", ())]
                comp, op = name.split(".", 1)
                self.operations[name] = OperationDef(comp, op, [(s[0], s[2]) for s in sig], sig)

    def _load_spacecraft(self, doc):
        pos = doc.get("position_scheduling")
        if pos:
            self.position_parameter = self.parameter(pos["parameter"])
        frames = doc.get("frames") or {}
        if "tm_vcs" in frames:
            self.tm_vcs = {str(k): _int(v, "TM VC of %s" % k) for k, v in frames["tm_vcs"].items()}
        if "scid" in frames:
            self.scid = _int(frames["scid"], "spacecraft id")
        self.frames = frames
        self.pus = doc.get("pus") or {}
        ids = set()
        for n in doc.get("nodes", []):
            nid = _int(n["node_id"], "node id of %s" % n["name"])
            if not 1 <= nid <= 127 or nid in ids or n["name"] in self.nodes:
                raise SdbError("node %s: id %d unusable or repeated" % (n["name"], nid))
            ids.add(nid)
            path = n.get("definition")
            if path and self.base and not path.startswith("/"):
                path = self.base + "/" + path
            role = n.get("role")
            if role not in (None, "nominal", "redundant"):
                raise SdbError(
                    "node %s: role %r, expected nominal or redundant" % (n["name"], role)
                )
            self.nodes[n["name"]] = NodeDef(n["name"], nid, path, role)

    def function(self, key):
        """The FunctionDef with this id or name ('SolarPanel.set_angle')."""
        f = self.functions.get(key) if isinstance(key, int) else self._functions_by_name.get(key)
        if f is None:
            raise UnknownNameError("function", key, known=self._functions_by_name)
        return f

    def _load_files(self, doc):
        for fs in doc.get("filestores", []):
            prefix = fs["prefix"]
            if not isinstance(prefix, str) or not prefix or ":" in prefix or "/" in prefix:
                raise SdbError("filestore prefix %r, expected a name like 'SAT'" % (prefix,))
            if prefix in self.filestores:
                raise SdbError("filestore prefix %s declared twice" % prefix)
            self.filestores[prefix] = _int(fs["entity"], "CFDP entity id of %s" % prefix)
            if fs.get("local") or self.local_filestore is None:
                self.local_filestore = prefix
        for m in doc.get("memories", []):
            mid = _int(m["id"], "memory id")
            if mid in self.memories:
                raise SdbError("memory %d declared twice" % mid)
            size = _int(m["size"], "size of memory %d" % mid)
            if size == 0:
                raise SdbError("memory %d has size 0" % mid)
            self.memories[mid] = {
                "id": mid,
                "name": m.get("name", "memory%d" % mid),
                "file": m.get("file"),
                "start": _int(m.get("start", 0), "start of memory %d" % mid),
                "size": size,
                "writable": bool(m.get("writable", False)),
                "mirror": m.get("mirror"),
                "objects": _memory_objects(m.get("objects", []), mid, size),
            }

    def filestore_entity(self, prefix):
        """The CFDP entity id of path prefix ``prefix`` ('SAT', 'GROUND')."""
        try:
            return self.filestores[prefix]
        except KeyError:
            raise UnknownNameError("filestore", prefix, known=self.filestores) from None

    def _add_parameter(self, p):
        if p.id in self.parameters:
            raise SdbError(
                "parameter id %d given to both %s and %s"
                % (p.id, self.parameters[p.id].qualified, p.qualified)
            )
        if p.qualified in self._params_by_name:
            raise SdbError("parameter %s declared twice" % p.qualified)
        self.parameters[p.id] = p
        self._params_by_name[p.qualified] = p

    def _add_event(self, component, e):
        what = "event %s" % e.get("name")
        ev = EventDef(
            _int(e["id"], "id of " + what),
            component,
            e["name"],
            _severity(e.get("severity", "info"), what),
            e.get("data", ()),
        )
        if ev.id in self.events:
            raise SdbError(
                "event id %d given to both %s and %s"
                % (ev.id, self.events[ev.id].qualified, ev.qualified)
            )
        if ev.qualified in self._events_by_name:
            raise SdbError("event %s declared twice" % ev.qualified)
        self.events[ev.id] = ev
        self._events_by_name[ev.qualified] = ev

    def parameter(self, key):
        """The Parameter with this id or qualified name ('SolarPanel.angle')."""
        p = self.parameters.get(key) if isinstance(key, int) else self._params_by_name.get(key)
        if p is None:
            raise UnknownNameError("parameter", key, known=self._params_by_name)
        return p

    def event(self, key):
        """The EventDef with this id or qualified name ('SolarPanel.angle_reached')."""
        e = self.events.get(key) if isinstance(key, int) else self._events_by_name.get(key)
        if e is None:
            raise UnknownNameError("event", key, known=self._events_by_name)
        return e

    def apid(self, name):
        try:
            return self.apids[name]
        except KeyError:
            raise UnknownNameError("APID named", name, known=self.apids) from None

    def check_interfaces(self, interfaces):
        """Raise SdbError if an entry names an attribute or event its interface lacks."""
        by_name = {i.name: i for i in interfaces}
        for p in self.parameters.values():
            itf = by_name.get(p.component)
            if itf is None:
                continue
            m = itf.members.get(p.name)
            if m is None or m.member != 1:
                raise SdbError("%s has no attribute %s" % (p.component, p.name))
            if p.writable and not m.writable:
                raise SdbError(
                    "%s is writable in the database, read-only in the interface" % p.qualified
                )
        for e in self.events.values():
            itf = by_name.get(e.component)
            if itf is None:
                continue
            m = itf.members.get(e.name)
            if m is None or m.member != 3:
                raise SdbError("%s has no event %s" % (e.component, e.name))


_KNOWN = (
    "$schema",  # the JSON Schema editors check the file with
    "mission",
    "apids",
    "components",
    "parameters",
    "events",
    "housekeeping",
    "filestores",
    "memories",
    "functions",
    "position_scheduling",
    "frames",
    "nodes",
    "pus",
    "services",
)


def parse_json(text):
    """The one place the database's JSON text is parsed."""
    try:
        return jsonsafe.loads(text)
    except ValueError as e:
        raise SdbError("spacecraft database is not valid JSON: %s" % e) from None


def loads(text, base=""):
    """Parse a spacecraft database from JSON text (``base``: folder of relative paths)."""
    return Sdb(parse_json(text), base)


def load(path):
    with open(path) as f:
        text = f.read()
    i = path.rfind("/")
    return loads(text, path[:i] if i > 0 else ("/" if i == 0 else ""))


def _memory_objects(items, mid, size):
    """The objects of memory ``mid`` (service 6 object memory): id -> (name, offset, size)."""
    out = {}
    for o in items:
        oid = _int(o["id"], "object id in memory %d" % mid)
        if oid == 0 or oid in out:
            raise SdbError("object %d of memory %d: 0 or declared twice" % (oid, mid))
        off = _int(o.get("offset", 0), "offset of object %d" % oid)
        n = _int(o["size"], "size of object %d" % oid)
        if n == 0 or off + n > size:
            raise SdbError("object %d of memory %d outside its %d octets" % (oid, mid, size))
        out[oid] = (o.get("name", "object%d" % oid), off, n)
    return out


def _names(defs):
    return [d.name for d in defs]
