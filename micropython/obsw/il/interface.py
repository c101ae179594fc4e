"""Component interfaces declared in one place: attributes, operations and events with ids.

An ``Interface`` is plain data shared by the provider and every user; proxies are built from
it. Ids are fixed numbers, unique within the interface, so the spacecraft database can map
attributes to PUS parameters and events to PUS event ids.

    SOLAR_PANEL = Interface("SolarPanel", 0x10, [
        Attribute("angle", 1, DATA, type="f32", unit="deg"),
        Attribute("speed", 2, CONFIGURATION, type="f32", unit="deg/s"),
        Operation("set_angle", 3, ("angle",)),
        Operation("deploy", 4, (), asynchronous=True),
        Event("angle_reached", 5, INFO),
    ])
"""

from obsw.compat import const

DATA = const(0)  # read-only attribute
CONFIGURATION = const(1)  # read-write attribute

# event severities, in the order of PUS service 5
INFO = const(1)
LOW = const(2)
MEDIUM = const(3)
HIGH = const(4)

ATTRIBUTE = const(1)
OPERATION = const(2)
EVENT = const(3)


def _check_name(name):
    if not isinstance(name, str) or not name or "." in name:
        raise ValueError("member name must be a non-empty str without '.', got %r" % (name,))


def _check_id(ident):
    if not isinstance(ident, int) or isinstance(ident, bool) or ident < 0:
        raise ValueError("id must be an int >= 0, got %r" % (ident,))


class Attribute:
    """A parameter of the component: ``DATA`` (read-only) or ``CONFIGURATION`` (read-write)."""

    member = ATTRIBUTE

    def __init__(self, name, id, kind=DATA, *, type=None, unit=None, description=""):
        _check_name(name)
        _check_id(id)
        if kind not in (DATA, CONFIGURATION):
            raise ValueError("attribute kind must be DATA or CONFIGURATION, got %r" % (kind,))
        self.name = name
        self.id = id
        self.kind = kind
        self.type = type
        self.unit = unit
        self.description = description

    @property
    def writable(self):
        return self.kind == CONFIGURATION

    def __repr__(self):
        return "Attribute(%r, %d, %s)" % (
            self.name,
            self.id,
            "CONFIGURATION" if self.kind else "DATA",
        )


class Operation:
    """A function with ``in`` parameters and one return value.

    Synchronous operations reply with their return value. Asynchronous ones are accepted at
    once; the provider's method gets a ``Job`` first and reports progress and the outcome
    through it, which reach the caller as status updates.
    """

    member = OPERATION

    def __init__(self, name, id, params=(), *, asynchronous=False, returns=None, description=""):
        _check_name(name)
        _check_id(id)
        for p in params:
            _check_name(p)
        self.name = name
        self.id = id
        self.params = tuple(params)
        self.asynchronous = asynchronous
        self.returns = returns
        self.description = description

    def __repr__(self):
        return "Operation(%r, %d, %r%s)" % (
            self.name,
            self.id,
            self.params,
            ", asynchronous" if self.asynchronous else "",
        )


class Event:
    """Something the component announces, with a payload of any size."""

    member = EVENT

    def __init__(self, name, id, severity=INFO, *, fields=(), description=""):
        _check_name(name)
        _check_id(id)
        if severity not in (INFO, LOW, MEDIUM, HIGH):
            raise ValueError("event severity must be INFO, LOW, MEDIUM or HIGH: %r" % (severity,))
        self.name = name
        self.id = id
        self.severity = severity
        self.fields = tuple(fields)
        self.description = description

    def __repr__(self):
        return "Event(%r, %d, severity=%d)" % (self.name, self.id, self.severity)


class Interface:
    """The declaration of a component: its name, id and members."""

    def __init__(self, name, id, members, *, description=""):
        _check_name(name)
        _check_id(id)
        self.name = name
        self.id = id
        self.description = description
        self.members = {}
        self.by_id = {}
        self.attributes = []
        self.operations = []
        self.events = []
        for m in members:
            if m.name in self.members:
                raise ValueError("%s declares %r twice" % (name, m.name))
            if m.id in self.by_id:
                raise ValueError(
                    "%s: id %d used by both %r and %r"
                    % (name, m.id, self.by_id[m.id].name, m.name)
                )
            self.members[m.name] = m
            self.by_id[m.id] = m
            if m.member == ATTRIBUTE:
                self.attributes.append(m)
            elif m.member == OPERATION:
                self.operations.append(m)
            elif m.member == EVENT:
                self.events.append(m)
            else:
                raise ValueError("%s: %r is not an Attribute, Operation or Event" % (name, m))

    def member(self, key):
        """The member called ``key`` (a name or a numeric id), or None."""
        if type(key) is str:
            return self.members.get(key)
        return self.by_id.get(key)

    def __repr__(self):
        return "Interface(%r, %d, %d members)" % (self.name, self.id, len(self.members))


def check_unique_ids(interfaces):
    """Raise ValueError if two interfaces share a name or an id."""
    names = {}
    ids = {}
    for itf in interfaces:
        if itf.name in names:
            raise ValueError("interface name %r declared twice" % itf.name)
        if itf.id in ids:
            raise ValueError("interface id %d used by %s and %s" % (itf.id, ids[itf.id], itf.name))
        names[itf.name] = itf
        ids[itf.id] = itf.name
