"""Names of component members as PLUTO procedures write them, and what is known about them.

A PLUTO object reference names a member of a component, innermost first: ``"angle of
SolarPanel"`` is ``SolarPanel.angle``. ``Catalog`` holds the members a spacecraft database
and component interfaces declare, by spelling-free names (``"set state bits of Cpdu N"``
finds ``CpduN.set_state_bits``); ``target_of`` turns a path into ``(component, member)``;
``plain`` turns procedure values into what the interaction layer carries.
"""

from obsw.pluto.system import argument_code, norm
from obsw.pluto.units import AbsTime, Quantity, UnitError, isdigits
from obsw.pluto.units import parse as parse_unit


class ParameterError(ValueError):
    """A parameter could not be read through the interaction layer."""

    def __init__(self, path, cause):
        super().__init__("%s: %s" % (path, cause))
        self.path = path
        self.cause = cause


def type_code(t):
    """PLUTO checker type code for a database or interface type name ('float32', 'u8'...)."""
    if isinstance(t, (list, tuple)) and len(t) == 2:
        return _PTC.get(t[0], "?")
    t = str(t or "").lower()
    if not t:
        return "?"
    if t.startswith("bool"):
        return "b"
    if t.startswith("f") or t in ("real", "double"):
        return "r"
    if t.startswith("uint") or t.startswith("int") or (t[0] in "ui" and isdigits(t[1:])):
        return "i"
    if t.startswith("str") or t == "text":
        return "s"
    return "?"


_PTC = {1: "b", 3: "i", 4: "i", 5: "r", 8: "s"}


def _unit(u):
    """``u`` if PLUTO (Annex B) knows it, else None (the value then counts as unitless)."""
    if not u:
        return None
    try:
        parse_unit(u)
    except (UnitError, ValueError):
        return None
    return u


# catalog entry fields
KIND = 0
COMPONENT = 1
MEMBER = 2
CODE = 3
UNIT = 4
PARAMS = 5
SIGNATURE = 6


class Catalog:
    """What is known about component members, by spelling-free (component, member) names.

    An entry is ``[kind, component, member, type code, unit, params, signature]``; ``kind``
    is "parameter", "activity" or "event"; ``params`` lists an operation's ``(name, unit)``;
    ``signature`` the arguments the database declares, ``(name, type code, unit)``.
    """

    def __init__(self, sdb=None, interfaces=()):
        self.entries = {}
        self.interfaces = {}  # names of interfaces added
        self.calibrated = {}  # "Component.attribute" -> sdb Parameter whose raw value differs
        self._paths = {}  # path -> entry or None, filled as paths are looked up
        if sdb is not None:
            self.add_sdb(sdb)
        for itf in interfaces or ():
            self.add_interface(itf)

    def add(self, kind, comp, member, code=None, unit=None, params=None, signature=None):
        key = (norm(comp), norm(member))
        e = self.entries.get(key)
        if e is None:
            self.entries[key] = [kind, comp, member, code, _unit(unit), params, signature]
        else:  # a second source fills in what the first left open
            if e[CODE] in (None, "?") and code:
                e[CODE] = code
            if not e[UNIT]:
                e[UNIT] = _unit(unit)
            if e[PARAMS] is None and params is not None:
                e[PARAMS] = params
            if e[SIGNATURE] is None and signature is not None:
                e[SIGNATURE] = signature
        self._paths = {}

    def add_interface(self, itf):
        """Attributes, operations and events of an ``obsw.il.interface.Interface``."""
        self.interfaces[itf.name] = itf
        for a in itf.attributes:
            self.add("parameter", itf.name, a.name, type_code(a.type), a.unit)
        for op in itf.operations:
            self.add("activity", itf.name, op.name, None, None, [(p, None) for p in op.params])
        for ev in itf.events:
            self.add("event", itf.name, ev.name)

    def add_sdb(self, sdb):
        """A spacecraft database: an ``obsw.pus.sdb.Sdb`` or its JSON document (a dict, parsed
        by that one parser). A request of a mission service is an activity under its own
        names too (``dipole of mtq`` is ``Magnetorquer.set_dipole``)."""
        if isinstance(sdb, dict):
            from obsw.pus.sdb import Sdb

            sdb = Sdb(sdb)
        for p in sdb.parameters.values():
            if p.component:
                code = type_code(p.type_spec)
                if p.calibration or p.labels:  # PLUTO sees the engineering value
                    self.calibrated[p.component + "." + p.name] = p
                    code = "r" if p.calibration else "s"
                self.add("parameter", p.component, p.name, code, p.unit)
        for op in sdb.operations.values():
            sig = None
            if op.signature is not None:
                sig = [(n, argument_code(t), _unit(u)) for n, t, u in op.signature]
                f = sdb._functions_by_name.get(op.qualified)
                if f is not None and f.labels:  # an enumeration: its labels, or their numbers
                    ids = {a[1]: a[0] for a in f.arguments}
                    for i, (n, _code, u) in enumerate(sig):
                        labels = f.labels.get(ids.get(n))
                        if labels:
                            sig[i] = (n, ("labels", labels), u)
            self.add("activity", op.component, op.name, None, None, list(op.arguments), sig)
        for e in sdb.events.values():
            if e.component:
                self.add("event", e.component, e.name)
        for svc in sdb.services.values():  # a mission service's request is an activity too
            for r in svc.requests.values():
                sig = [(f.name, argument_code(f.type_spec), _unit(f.unit)) for f in r.fields]
                params = [(f.name, f.unit) for f in r.fields]
                entry = ["activity", svc.component, r.operation, None, None, params, sig]
                self.entries[(norm(svc.name), norm(r.name))] = entry
        self._paths = {}

    def find(self, path):
        """The entry a PLUTO path names, or None."""
        if path in self._paths:
            return self._paths[path]
        names = path.split(" of ")
        if len(names) > 2 and names[0] == "value":
            names = names[1:]
        e = None
        if len(names) > 1:
            e = self.entries.get(("".join([norm(n) for n in names[:0:-1]]), norm(names[0])))
        else:
            n = norm(names[0])
            for (c, m), x in self.entries.items():
                if m + c == n or c + m == n:
                    e = x
                    break
        self._paths[path] = e
        return e

    def unit_of(self, comp, name):
        """Unit of ``comp``'s attribute called ``name`` (an argument's default unit)."""
        e = self.entries.get((norm(comp), norm(name)))
        return e[UNIT] if e is not None and e[KIND] == "parameter" else None


def target_of(path, entry=None):
    """``(component, member)`` of a PLUTO path (from its catalog entry when there is one)."""
    if entry is not None:
        return entry[COMPONENT], entry[MEMBER]
    names = path.split(" of ")
    if len(names) > 2 and names[0] == "value":
        names = names[1:]
    if len(names) < 2:
        raise ParameterError(path, "names no member of a component ('<member> of <component>')")
    comp = "".join(names[:0:-1]).replace(" ", "")
    return comp, names[0].strip().replace(" ", "_")


def plain(v, unit=None):
    """A procedure value as the interaction layer carries it: numbers in ``unit``."""
    if isinstance(v, Quantity):
        return v.to(unit).value if unit else v.value
    if isinstance(v, AbsTime):
        return v.seconds
    if isinstance(v, dict):
        return {k: plain(x) for k, x in v.items()}
    if isinstance(v, list):
        return [plain(x) for x in v]
    return v
