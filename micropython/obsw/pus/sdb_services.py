"""Mission-specific PUS services (service types 128..255) as the spacecraft database declares them.

    "services": [
      {"type": 140, "name": "mtq", "component": "Magnetorquer",
       "requests": [
         {"subtype": 1, "name": "dipole", "operation": "set_dipole", "report": 2,
          "arguments": [{"name": "x", "type": "float32", "unit": "A.m^2",
                         "range": [-0.2, 0.2]}, ..]},
         {"subtype": 3, "name": "degauss", "operation": "degauss"}],
       "reports": [
         {"subtype": 2, "name": "dipole_report",
          "fields": [{"name": "magnitude", "type": "float32", "unit": "A.m^2"}]},
         {"subtype": 4, "name": "saturation", "event": "saturated",
          "fields": [{"name": "axis", "type": "string"}, ..]}]}
    ]

ECSS-E-ST-70-41C leaves service types 128..255 to the mission (clause 6.1.3). A request is a
TC[type, subtype] whose application data is its arguments, in order, each of its declared
packet field type; it calls ``operation`` of ``component`` over the interaction layer with
them. A request's ``report`` names the subtype of the TM that carries the operation's
return value (a dict by field name, a list in field order, or a single value); a report
with ``event`` is sent, unsolicited, whenever the component publishes that event. A
subtype is used once per service, by a request or a report (the standard numbers TC and TM
subtypes of a service apart). ``range`` ([low, high], inclusive) bounds an argument's value.
"""

from obsw.pus.sdb import SdbError, field_type
from obsw.pus.structure import Structure

FIRST_MISSION_TYPE = 128  # service types below are the standard's
LAST_MISSION_TYPE = 255


class FieldDef:
    """A typed argument or report field: name, type spec, packet field type, unit, range."""

    __slots__ = ("name", "type_spec", "type", "unit", "range", "description")

    def __init__(self, spec, where):
        self.name = spec["name"]
        if not isinstance(self.name, str) or not self.name:
            raise SdbError("%s: a field name must be a non-empty string" % where)
        self.type_spec = spec["type"]
        self.type = field_type(self.type_spec, "%s, %s" % (where, self.name))
        self.unit = spec.get("unit")
        self.description = spec.get("description")
        r = spec.get("range")
        if r is not None:
            if not isinstance(r, (list, tuple)) or len(r) != 2 or r[0] > r[1]:
                raise SdbError("%s, %s: range %r, expected [low, high]" % (where, self.name, r))
            for bound in r:
                try:
                    self.type.check(bound)
                except (ValueError, TypeError) as e:
                    raise SdbError("%s, %s: range %s" % (where, self.name, e)) from None
            r = (r[0], r[1])
        self.range = r

    def out_of_range(self, value):
        """None if ``value`` lies in the range (or there is none), else why not."""
        r = self.range
        if r is None or r[0] <= value <= r[1]:
            return None
        return "%s = %r outside [%r, %r]%s" % (
            self.name,
            value,
            r[0],
            r[1],
            " " + self.unit if self.unit else "",
        )


def _fields(items, where):
    out = []
    seen = set()
    for spec in items or ():
        f = FieldDef(spec, where)
        if f.name in seen:
            raise SdbError("%s declares %s twice" % (where, f.name))
        seen.add(f.name)
        out.append(f)
    return out


class MessageDef:
    """A request (TC) or report (TM) of a mission service, with its typed data layout."""

    def __init__(self, service, spec, kind):
        self.service = service  # the ServiceDef
        self.kind = kind  # "request" or "report"
        self.subtype = spec["subtype"]
        if not isinstance(self.subtype, int) or not 1 <= self.subtype <= 255:
            raise SdbError(
                "service %s: %s subtype %r, expected 1..255" % (service.name, kind, self.subtype)
            )
        self.name = spec["name"]
        self.description = spec.get("description")
        where = "service %s %s %s" % (service.name, kind, self.name)
        self.fields = _fields(spec.get("arguments" if kind == "request" else "fields"), where)
        self.layout = Structure([(f.name, f.type) for f in self.fields])
        self.operation = spec.get("operation") if kind == "request" else None
        self.report = spec.get("report") if kind == "request" else None
        self.event = spec.get("event") if kind == "report" else None
        if kind == "request" and not isinstance(self.operation, str):
            raise SdbError("%s: operation %r, expected its name" % (where, self.operation))

    @property
    def message_type(self):
        return (self.service.type, self.subtype)

    @property
    def qualified(self):
        return "%s.%s" % (self.service.name, self.name)

    def values(self, given):
        """{field name: value} from a dict, a list in field order or a single value."""
        if isinstance(given, dict):
            return given
        if given is None:
            given = ()
        elif not isinstance(given, (list, tuple)):
            given = (given,)
        return dict(zip([f.name for f in self.fields], given))

    def pack(self, given):
        return self.layout.pack(self.values(given))

    def unpack(self, data):
        return self.layout.unpack(data)

    def __repr__(self):
        return "%s(%d,%d %s)" % (self.kind, self.service.type, self.subtype, self.qualified)


class ServiceDef:
    """A mission service: its type, name, component, requests and reports by subtype."""

    def __init__(self, spec):
        self.type = spec["type"]
        self.name = spec["name"]
        if not isinstance(self.name, str) or not self.name:
            raise SdbError("service %r: a name must be a non-empty string" % (self.type,))
        t = self.type
        if not isinstance(t, int) or not FIRST_MISSION_TYPE <= t <= LAST_MISSION_TYPE:
            raise SdbError(
                "service %s: type %r, expected %d..%d (the mission's service types)"
                % (self.name, t, FIRST_MISSION_TYPE, LAST_MISSION_TYPE)
            )
        self.component = spec["component"]
        self.description = spec.get("description")
        self.requests = {}  # subtype -> MessageDef
        self.reports = {}  # subtype -> MessageDef
        self._by_name = {}
        for kind, table, key in (
            ("request", self.requests, "requests"),
            ("report", self.reports, "reports"),
        ):
            for item in spec.get(key, ()):
                m = MessageDef(self, item, kind)
                if m.subtype in self.requests or m.subtype in self.reports:
                    raise SdbError(
                        "service %s: subtype %d declared twice" % (self.name, m.subtype)
                    )
                if m.name in self._by_name:
                    raise SdbError("service %s: %s declared twice" % (self.name, m.name))
                table[m.subtype] = m
                self._by_name[m.name] = m
        for r in self.requests.values():
            if r.report is not None and r.report not in self.reports:
                raise SdbError(
                    "service %s request %s: report %r is not a report subtype of the service"
                    % (self.name, r.name, r.report)
                )

    def message(self, key):
        """The request or report with this subtype or name."""
        m = self._by_name.get(key) if isinstance(key, str) else None
        if m is None:
            m = self.requests.get(key) or self.reports.get(key)
        if m is None:
            raise KeyError("service %s has no request or report %r" % (self.name, key))
        return m

    def request(self, key):
        m = self.message(key)
        if m.kind != "request":
            raise KeyError("%s is a report of service %s, not a request" % (m.name, self.name))
        return m

    def operation(self, request):
        """The "Component.operation" a request calls."""
        return "%s.%s" % (self.component, request.operation)

    def __repr__(self):
        return "ServiceDef(%d, %s)" % (self.type, self.name)


def load_services(items, standard=()):
    """The ``services`` section: type -> ServiceDef (types and names once each)."""
    out = {}
    names = set()
    for spec in items or ():
        s = ServiceDef(spec)
        if s.type in out or s.type in standard:
            raise SdbError("service type %d declared twice" % s.type)
        if s.name in names:
            raise SdbError("service %s declared twice" % s.name)
        names.add(s.name)
        out[s.type] = s
    return out


def signatures(services):
    """The activity signatures the requests give PLUTO: {"Component.operation": [(name,
    type, unit), ..]}, for operations the database's components do not declare."""
    out = {}
    for s in services.values():
        for r in s.requests.values():
            out[s.operation(r)] = [(f.name, f.type_spec, f.unit) for f in r.fields]
    return out
