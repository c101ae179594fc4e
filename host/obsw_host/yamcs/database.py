"""The spacecraft database as the XTCE generator sees it: one adapter over ``obsw.pus.sdb``.

Everything the Yamcs side reads from the database goes through ``load(path)``, which returns
plain records (``Spacecraft``, ``Param``, ``Event``, ``Function``, ``Structure``). The
database file is parsed and checked by the project's own loader, which also keeps the optional
entries for mission control (units, limits, calibrations, ranges of writable parameters), on
each attribute or parameter:

    {"name": "speed", "parameter": 2, "type": "float32", "unit": "deg/s", "writable": true,
     "range": [0, 10],
     "limits": {"warning": [0.5, 8], "critical": [0, 9.5]},
     "calibration": {"polynomial": [0, 1]}}

``calibration`` is a polynomial (coefficients from the constant term up) or a spline
(``{"spline": [[raw, eng], ...]}``) from the raw value to the engineering value.
"""

from obsw.pus import sdb as sdb_module

from obsw_host.mission.ids import MissionIds


class Param:
    """One PUS parameter: id, space system path parts, type pair and optional extras."""

    def __init__(self, pid, qualified, pair, unit, writable, extra):
        self.id = pid
        self.qualified = qualified
        self.path = qualified.split(".")  # 'SolarPanel.angle' -> ['SolarPanel', 'angle']
        self.pair = pair
        self.unit = unit
        self.writable = writable
        self.range = extra.get("range")
        self.limits = extra.get("limits")
        self.calibration = extra.get("calibration")
        self.labels = extra.get("labels")  # {raw value: label} of an enumeration, or None
        self.description = extra.get("description")


class Event:
    """One PUS event: id, qualified name, severity 1..4 and its auxiliary data fields."""

    def __init__(self, eid, qualified, severity, fields):
        self.id = eid
        self.qualified = qualified
        self.path = qualified.split(".")
        self.severity = severity
        self.fields = fields  # [(name, (ptc, pfc), {raw: label} or None)]


class Function:
    """One service 8 function: id, qualified name and its arguments [(id, name, pair,
    {raw: label} or None)]."""

    def __init__(self, fid, qualified, arguments):
        self.id = fid
        self.qualified = qualified
        self.path = qualified.split(".")
        self.arguments = arguments


class Structure:
    """One housekeeping report structure: SID, interval and its parameter ids in order."""

    def __init__(self, sid, interval, parameters, enabled):
        self.sid = sid
        self.interval = interval
        self.parameters = parameters
        self.enabled = enabled


class Spacecraft:
    """What the Yamcs instance needs to know of the spacecraft database."""

    def __init__(
        self, mission, apids, params, events, functions, structures, filestores, ids=None
    ):
        self.mission = mission or "spacecraft"
        self.ids = (
            ids  # the mission's ids (obsw_host.mission.ids.MissionIds): SCID, VCs, source id
        )
        self.apids = apids
        self.params = params  # id -> Param
        self.events = events  # id -> Event
        self.functions = functions  # id -> Function
        self.structures = structures  # [Structure]
        self.filestores = filestores  # prefix -> CFDP entity id
        self.services = {}  # mission services (types 128..255): type -> sdb_services.ServiceDef

    def apid(self, name, default=None):
        return self.apids.get(name, default)

    def required_apid(self, name):
        """The APID named ``name``; a MissionError naming the file and key when missing."""
        if self.ids is None:
            raise KeyError("no APID named %r in the spacecraft database" % (name,))
        return self.ids.apid(name)


def _pair(type_spec):
    if isinstance(type_spec, str):
        return sdb_module.TYPES[type_spec]
    return tuple(type_spec)


def loads(text, path=None):
    """The Spacecraft of a database given as JSON text (SdbError when it is malformed)."""
    db = sdb_module.loads(text)
    return from_sdb(db, MissionIds(db, path))


def from_ids(ids):
    """The Spacecraft of a mission's ids (``obsw_host.mission.ids.MissionIds``)."""
    return from_sdb(ids.sdb, ids)


def from_sdb(db, ids):
    """The Spacecraft of a parsed database ``db`` whose ids are ``ids``."""
    params = {}
    for pid, p in db.parameters.items():
        extra = {
            "range": p.range,
            "limits": p.limits,
            "calibration": p.calibration,
            "labels": p.labels,
            "description": p.description,
        }
        params[pid] = Param(pid, p.qualified, _pair(p.type_spec), p.unit, p.writable, extra)
    events = {}
    for eid, e in db.events.items():
        labels = getattr(e, "labels", None) or {}
        fields = [(name, _pair(spec), labels.get(name)) for name, spec in e.type_specs]
        events[eid] = Event(eid, e.qualified, e.severity, fields)
    functions = {}
    for fid, f in db.functions.items():
        labels = getattr(f, "labels", None) or {}
        args = [(aid, name, _pair(spec), labels.get(aid)) for aid, name, spec, _ in f.arguments]
        functions[fid] = Function(fid, f.name, args)
    structures = [
        Structure(h["sid"], h["interval"], list(h["parameters"]), h["enabled"])
        for h in db.housekeeping
    ]
    sc = Spacecraft(
        db.mission,
        dict(db.apids),
        params,
        events,
        functions,
        structures,
        dict(db.filestores),
        ids,
    )
    sc.services = dict(db.services)  # the mission's own services: type -> ServiceDef
    return sc


def load(path):
    """The Spacecraft of the database file ``path``."""
    with open(path) as f:
        return loads(f.read(), path)
