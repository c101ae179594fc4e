"""What the OBC would otherwise find out only while it runs, checked before anything starts.

``obsw_host.mission.check`` calls these with its checker (``add(file, path, text)``): each
looks at the mission as the OBC's own code will use it, and a mission they accept starts
every process and means what it says:

- ``options``: a component's ``options`` against its class's constructor;
- ``attributes``: each database attribute and event of a component against the component's
  interface (present, the database type at least as wide as the component's value, writable
  only if the component's attribute is);
- ``power_cycle``: the platform's power-cycle component has ``power_cycle(line, off_ms)``;
- ``monitoring``: ``pus.monitoring`` through the very code that installs it
  (``obsw_host.obc.monitoring``), events and parameters by name;
- ``defaults``: each parameter's ``default`` (an engineering value) has a raw value of its type;
- ``housekeeping``: each report structure fits in the largest packet (``largest_packet``).
"""

import inspect

from obsw.pus.config import from_sdb
from obsw.pus.parameters import ParameterPool
from obsw.pus.services.s12_monitoring import OnBoardMonitoring

from obsw_host.mission.errors import did_you_mean, short

UDP_PAYLOAD = 65507  # the largest UDP datagram over IPv4: what one TM packet may be on the OBC

# a component attribute's type -> (bounds of an integer, or None) and the database types that
# hold every value of it, narrowest first
_INT = {
    "u8": (0, 0xFF),
    "u16": (0, 0xFFFF),
    "u32": (0, 0xFFFFFFFF),
    "u64": (0, 0xFFFFFFFFFFFFFFFF),
    "i8": (-0x80, 0x7F),
    "i16": (-0x8000, 0x7FFF),
    "i32": (-0x80000000, 0x7FFFFFFF),
    "i64": (-0x8000000000000000, 0x7FFFFFFFFFFFFFFF),
}
_SDB_INT = {
    "uint8": (0, 0xFF),
    "enum8": (0, 0xFF),
    "uint16": (0, 0xFFFF),
    "enum16": (0, 0xFFFF),
    "uint32": (0, 0xFFFFFFFF),
    "uint64": (0, 0xFFFFFFFFFFFFFFFF),
    "int8": (-0x80, 0x7F),
    "int16": (-0x8000, 0x7FFF),
    "int32": (-0x80000000, 0x7FFFFFFF),
    "int64": (-0x8000000000000000, 0x7FFFFFFFFFFFFFFF),
}
_KNOWN = tuple(_INT) + ("f32", "f64", "bool", "str")
_EXACT_IN_FLOAT = {"float32": 24, "float64": 53}  # integer bits a float holds exactly


def _holds(comp_type, sdb_type):
    """True if database type ``sdb_type`` holds every value of component type ``comp_type``;
    None if either type says nothing the check knows (an unknown one is said elsewhere)."""
    if sdb_type not in _SDB_INT and sdb_type not in ("bool", "float32", "float64", "string"):
        return None if sdb_type != "octets" or comp_type not in _KNOWN else False
    if comp_type in _INT:
        lo, hi = _INT[comp_type]
        if sdb_type in _SDB_INT:
            a, b = _SDB_INT[sdb_type]
            return a <= lo and hi <= b
        if sdb_type in _EXACT_IN_FLOAT:
            return max(hi, -lo).bit_length() <= _EXACT_IN_FLOAT[sdb_type]
        return False
    if comp_type == "f32":
        return sdb_type in ("float32", "float64")
    if comp_type == "f64":
        return sdb_type == "float64"
    if comp_type == "bool":
        return sdb_type == "bool" or sdb_type in _SDB_INT
    if comp_type == "str":
        return sdb_type == "string"
    return None


def _narrowest(comp_type):
    """The narrowest database type that holds ``comp_type``, for the message."""
    names = ("bool",) + tuple(_SDB_INT) + ("float32", "float64", "string")
    found = [n for n in names if _holds(comp_type, n)]
    return found[0] if len(found) == 1 else "%s or a wider type" % found[0]


def _dicts(items):
    if not isinstance(items, list):
        return []
    return [(i, x) for i, x in enumerate(items) if isinstance(x, dict)]


# ------------------------------------------------------------------------ component options


def options(c, name, spec, cls):
    """The mission's ``options`` of component ``name`` bind to ``cls``'s constructor."""
    opts = spec.get("options", {})
    if not isinstance(opts, dict):
        return
    try:
        sig = inspect.signature(cls)
    except (TypeError, ValueError):  # a constructor in C: nothing to compare with
        return
    params = sig.parameters
    named = [n for n, p in params.items() if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]
    takes_any = any(p.kind == p.VAR_KEYWORD for p in params.values())
    at = ["components", name, "options"]
    for key in opts:
        if key not in named and not takes_any:
            c.add(c.file, at + [key], "%s(...) takes no option %s; expected one of %s%s" % (
                cls.__name__, short(key), ", ".join(named) or "none",
                did_you_mean(key, named)))  # fmt: skip
            return
    try:
        sig.bind(**opts)
    except TypeError as e:
        c.add(c.file, at, "%s(**options): %s; expected the constructor's arguments (%s)"
              % (cls.__name__, e, ", ".join(named)))  # fmt: skip


# ------------------------------------------------------------------------ database vs components


def attributes(c, f, doc, interfaces):
    """Each attribute and event the database gives a component its interface has."""
    for ci, comp in _dicts(doc.get("components")):
        itf = interfaces.get(comp.get("name"))
        if itf is None:
            continue
        mine = {n: m for n, m in itf.members.items() if m.member == 1}
        events = [n for n, m in itf.members.items() if m.member == 3]
        for ai, a in _dicts(comp.get("attributes")):
            _attribute(c, f, ["components", ci, "attributes", ai], itf.name, a, mine)
        for ei, e in _dicts(comp.get("events")):
            name = e.get("name")
            if isinstance(name, str) and name not in events:
                c.add(f, ["components", ci, "events", ei, "name"], "%s has no event %s; "
                      "expected one of its interface's events (%s)%s" % (itf.name, name,
                      ", ".join(events) or "none", did_you_mean(name, events)))  # fmt: skip


def _attribute(c, f, at, comp, a, mine):
    name, sdb_type = a.get("name"), a.get("type")
    if not isinstance(name, str):
        return
    m = mine.get(name)
    if m is None:
        c.add(f, at + ["name"], "%s has no attribute %s; expected one of its interface's "
              "attributes (%s)%s" % (comp, name, ", ".join(mine) or "none",
                                     did_you_mean(name, mine)))  # fmt: skip
        return
    if a.get("writable") is True and not m.writable:
        c.add(f, at + ["writable"], "%s.%s is read-only in the component's interface (DATA); "
              "expected no writable, or a CONFIGURATION attribute" % (comp, name))  # fmt: skip
    if isinstance(sdb_type, str) and _holds(m.type, sdb_type) is False:
        c.add(f, at + ["type"], "%s cannot hold %s.%s, a %s in the component; expected %s"
              % (sdb_type, comp, name, m.type, _narrowest(m.type)))  # fmt: skip


def power_cycle(c):
    """The component the platform asks to power-cycle the OBC has ``power_cycle``."""
    platform = c.doc.get("platform") if isinstance(c.doc.get("platform"), dict) else {}
    pc = platform.get("power_cycle")
    if not isinstance(pc, dict) or not isinstance(pc.get("component"), str):
        return
    itf = c.interfaces.get(pc["component"])
    if itf is None:
        return  # no such node: said where the nodes are checked
    op = itf.members.get("power_cycle")
    if op is None or op.member != 2 or len(op.params) != 2:
        ops = sorted(n for n, m in itf.members.items() if m.member == 2)
        c.add(c.file, ["platform", "power_cycle", "component"], "%s has no operation "
              "power_cycle(line, off_ms); expected a node whose definition has that function "
              "(it has %s)" % (itf.name, ", ".join(ops) or "none"))  # fmt: skip


# ------------------------------------------------------------------------ what the OBC installs


def monitoring(c, sdb):
    """``pus.monitoring`` as the PUS process will install it."""
    from obsw_host.obc.monitoring import MonitoringError, definition

    pus = c.doc.get("pus") if isinstance(c.doc.get("pus"), dict) else {}
    entries = _dicts(pus.get("monitoring"))
    if not entries:
        return
    params = [p.qualified for p in sdb.parameters.values()]
    events = [e.qualified for e in sdb.events.values()]
    s12 = OnBoardMonitoring(ParameterPool(sdb), sdb.events)
    pmons = {}
    for i, e in entries:
        at = ["pus", "monitoring", i]
        bad = False
        for key, known, what in (("parameter", params, "parameter"),
                                 ("low_event", events, "event"),
                                 ("high_event", events, "event")):  # fmt: skip
            name = e.get(key)
            if isinstance(name, str) and name and name not in known:
                c.add(c.file, at + [key], "no %s %s in the database; expected one of its %ss%s"
                      % (what, short(name), what, did_you_mean(name, known)))  # fmt: skip
                bad = True
        if bad:
            continue
        p = sdb.parameter(e["parameter"]) if isinstance(e.get("parameter"), str) else None
        if p is not None and p.type.ptc not in (2, 3, 4, 5):
            c.add(c.file, at + ["parameter"], "%s is a %s; expected a numeric parameter for a "
                  "limit check" % (p.qualified, p.type_spec))  # fmt: skip
            continue
        try:
            d = definition(sdb, i, e)
            s12.check_definition(d)
        except MonitoringError as x:
            why = x.problems[0].text
            c.add(c.file, at, "%s; expected limits in the parameter's engineering units" % why)
            continue
        except Exception as x:  # PusFailure: what a TC[12,5] would be refused for
            c.add(c.file, at, "%s; expected a definition service 12 accepts" % x)
            continue
        fits = _raw_fits(p, d)
        if fits:
            c.add(c.file, at, fits)
        elif d["pmon"] in pmons:
            c.add(c.file, at + ["pmon"], "PMON %d is also pus.monitoring[%d]'s; expected "
                  "each PMON once" % (d["pmon"], pmons[d["pmon"]]))  # fmt: skip
        pmons.setdefault(d["pmon"], i)


def _raw_fits(p, d):
    """None if the raw limits of definition ``d`` fit parameter ``p``'s type, else why not."""
    for key in ("low", "high"):
        try:
            p.type.pack(d[key])
        except (ValueError, TypeError, OverflowError):
            return ("%s limit is raw %s, which %s cannot hold; expected limits within the "
                    "parameter's type" % (key, d[key], p.type_spec))  # fmt: skip
    return None


def largest_packet(sdb):
    """Octets of the largest TM packet the OBC sends: the packet length field's bound or a
    UDP datagram's, whichever is smaller."""
    return min(from_sdb(sdb).max_packet_size, UDP_PAYLOAD)


def report_octets(sdb, parameters):
    """The smallest TM[3,25] packet of a structure of ``parameters`` (ids or names): fixed
    fields at their size, strings and octets empty."""
    config = from_sdb(sdb)
    bits = 16  # the structure id
    for ref in parameters:
        t = sdb.parameter(ref).type
        bits += t.bits if t.bits else getattr(t, "length_bits", 0)
    return config.tm_min_size + (bits + 7) // 8


def housekeeping(c, sdb):
    """Each report structure fits in the largest packet."""
    limit = largest_packet(sdb)
    for i, hk in enumerate(sdb.housekeeping):
        n = report_octets(sdb, hk.get("parameters", ()))
        if n > limit:
            c.add(c.sdb_file, ["housekeeping", i, "parameters"], "its report is at least %d "
                  "octets; expected at most %d (the largest packet): split the structure"
                  % (n, limit))  # fmt: skip


def defaults(c, sdb):
    """Each ``default`` (engineering) has the raw value the pool will give before any other."""
    where = {}
    for ci, comp in _dicts(c.sdb_doc.get("components")):
        for ai, a in _dicts(comp.get("attributes")):
            where["%s.%s" % (comp.get("name"), a.get("name"))] = [
                "components",
                ci,
                "attributes",
                ai,
            ]
    for pi, p in _dicts(c.sdb_doc.get("parameters")):
        where[p.get("name")] = ["parameters", pi]
    for p in sdb.parameters.values():
        if p.default is None or p.values is None:
            continue
        try:
            p.type.check(p.to_raw(p.default))
        except ValueError as e:  # CalibrationError and FieldValueError are ValueErrors
            c.add(c.sdb_file, where.get(p.qualified, ["parameters"]) + ["default"], "%s has no "
                  "raw value (%s); expected an engineering value the calibration reaches"
                  % (short(p.default), e))  # fmt: skip
