"""The whole mission folder checked before anything starts: ``check(path) -> (Mission, problems)``;
``load(path)`` is the checked ``Mission`` or a ``MissionError`` listing every problem.

First each file against its JSON Schema (``schema/``), then what a schema cannot say, in
Python: names and ids given twice, references between the files (housekeeping, functions,
positions, nodes, procedures against the database and the components), the shapes of
``range``, ``limits`` and ``calibration``, processes naming known kinds or declared components.
Entries the schema already refused are skipped here, so one mistake gives one line. Last,
what the OBC would otherwise find out only while it runs (``crosscheck``: the database against
the components, component options, monitoring, report sizes): a mission that passes starts
every process, and its database means what it says.
"""

import glob
import os

from obsw.pluto.interp import load as load_procedure
from obsw.pluto.lexer import PlutoError
from obsw.pluto.names import CODE, KIND, UNIT, Catalog
from obsw.pus import sdb as sdb_module
from obsw.spacecan.equipment import equipment_interface
from obsw.spacecan.nodedef import NodeDefinition, NodeDefinitionError

from obsw_host.mission import crosscheck, defaults
from obsw_host.mission.config import ConfigError, MissionConfig
from obsw_host.mission.errors import MissionError, Problem, did_you_mean, display, short
from obsw_host.mission.folder import MAX_PROCEDURE, locate, read_text
from obsw_host.mission.schema import json_type, read_json, validate
from obsw_host.obc.onboard_time import ONBOARD_TIME
from obsw_host.obc.passes import PASSES
from obsw_host.obc.plugins import Component, PluginError
from obsw_host.obc.registry import KINDS, WITH_PUS
from obsw_host.update.component import SOFTWARE

_INT_BOUNDS = {
    "uint8": (0, 0xFF),
    "uint16": (0, 0xFFFF),
    "uint32": (0, 0xFFFFFFFF),
    "uint64": (0, 0xFFFFFFFFFFFFFFFF),
    "int8": (-0x80, 0x7F),
    "int16": (-0x8000, 0x7FFF),
    "int32": (-0x80000000, 0x7FFFFFFF),
    "int64": (-0x8000000000000000, 0x7FFFFFFFFFFFFFFF),
    "enum8": (0, 0xFF),
    "enum16": (0, 0xFFFF),
}
_NUMERIC = tuple(_INT_BOUNDS) + ("float32", "float64")
RENAMED_KINDS = {"solar_panel": "SolarPanel"}  # format-1 kinds that are components now


class Mission:
    """A checked mission folder: its file, ``config`` (``MissionConfig``), ``sdb`` (the parsed
    database, read once), node definitions and the interfaces of its components."""

    def __init__(self, config, sdb, interfaces):
        self.config = config
        self.path = config.path
        self.dir = config.dir
        self.name = config.name
        self.sdb = sdb
        self.interfaces = interfaces

    def __repr__(self):
        return "Mission(%r, %s)" % (self.name, self.path)


def _dicts(items):
    """(index, entry) of the objects in list ``items`` (anything else: the schema said so)."""
    if not isinstance(items, list):
        return []
    return [(i, x) for i, x in enumerate(items) if isinstance(x, dict)]


def _is_int(v):
    return isinstance(v, int) and not isinstance(v, bool)


def _is_num(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _pair(v):
    return isinstance(v, list) and len(v) == 2 and all(_is_num(x) for x in v)


class _Checker:
    def __init__(self, mission_file):
        self.file = mission_file
        self.folder = os.path.dirname(os.path.abspath(mission_file))
        self.problems = []
        # component name -> Interface (the OBC's built-in ones, plug-ins and nodes)
        self.interfaces = {ONBOARD_TIME.name: ONBOARD_TIME, SOFTWARE.name: SOFTWARE,
                           PASSES.name: PASSES}  # fmt: skip
        self.unresolved = set()  # components whose module is at fault (said once, there)
        self.where = {}  # kind or component -> the process that runs it
        self.nodes = {}  # SpaceCAN node name -> node id, of the definitions that load
        self.sdb_file = self.procedures = None

    def add(self, file, path, text):
        self.problems.append(Problem(file, path, text))

    # -------------------------------------------------------------------- the mission file

    def mission(self):
        doc, problems = read_json(self.file, self.folder)
        self.problems += problems
        if doc is None:
            return None
        if isinstance(doc, dict) and "format" not in doc and self._database_given(doc):
            return None
        if isinstance(doc, dict) and "format" not in doc and "processes" not in doc:
            self.add(self.file, "$", "not a mission file (no format, no processes); expected a "
                     "mission folder or its mission.json")  # fmt: skip
            return None
        if isinstance(doc, dict) and "format" not in doc:
            self.add(
                self.file,
                "$",
                'a format-1 mission file (no "format"); expected format '
                "%d: `obsw mission upgrade %s` converts it" % (defaults.FORMAT, self.file),
            )
            return None
        self.problems += validate(doc, defaults.MISSION_SCHEMA, self.file)
        if not isinstance(doc, dict):
            return None
        self.doc = doc
        self._components(doc)
        self._processes(doc)
        self._paths(doc)
        self._orbit_and_stations(doc)
        return doc

    def _database_given(self, doc):
        """True (and the problem said) if ``doc`` is a spacecraft database, not a mission
        file: the line names the mission folder to give instead."""
        if not (isinstance(doc.get("mission"), str) or isinstance(doc.get("components"), list)):
            return False
        found = None
        for name in sorted(os.listdir(self.folder)):
            if name.endswith(".json") and os.path.join(self.folder, name) != self.file:
                other, _ = read_json(os.path.join(self.folder, name), self.folder)
                if isinstance(other, dict) and "format" in other:
                    found = os.path.join(self.folder, name)
                    if name == defaults.MISSION_FILE:
                        found = self.folder
                    break
        where = "the mission folder %s" % display(found) if found else "its mission folder"
        self.add(self.file, "$", "a spacecraft database, not a mission file; expected %s "
                 "(whose mission file names this database)" % where)  # fmt: skip
        return True

    def _components(self, doc):
        comps = doc.get("components")
        if not isinstance(comps, dict):
            return
        for name, spec in comps.items():
            if name in KINDS:
                self.add(self.file, ["components", name], "%r is a built-in kind; expected "
                         "another name for the mission's component" % name)  # fmt: skip
                continue
            if not isinstance(spec, dict) or not isinstance(spec.get("module"), str):
                continue
            try:
                itf, cls = Component(name, spec, self.folder).check()
            except PluginError as e:
                text = str(e)[len(e.key) + 2 :]
                if "; expected" not in text:
                    text += "; expected a module with the Interface %s and its class" % name
                self.add(self.file, ["components", name, e.key.rsplit(".", 1)[1]], text)
                self.unresolved.add(name)
                continue
            self.interfaces[name] = itf
            crosscheck.options(self, name, spec, cls)

    def _processes(self, doc):
        procs = doc.get("processes")
        if not isinstance(procs, dict):
            return
        comps = doc.get("components") if isinstance(doc.get("components"), dict) else {}
        known = list(KINDS) + list(comps)
        where = {}
        for pname, kinds in procs.items():
            if not isinstance(kinds, list):
                continue
            for i, k in enumerate(kinds):
                if not isinstance(k, str):
                    continue
                at = ["processes", pname, i]
                if k not in known:
                    hint = did_you_mean(k, known)
                    if k in RENAMED_KINDS:
                        hint = " (the %s kind is now the component %s: `obsw mission upgrade`)" % (
                            k, RENAMED_KINDS[k])  # fmt: skip
                    self.add(self.file, at, "unknown kind %s; expected one of %s or a name of "
                             "components%s" % (short(k), ", ".join(KINDS), hint))  # fmt: skip
                elif k in where:
                    self.add(self.file, at, "%s already runs in process %s; expected each kind "
                             "in one process" % (short(k), short(where[k])))  # fmt: skip
                else:
                    where[k] = pname
        for k in WITH_PUS:
            if k in where and "pus" in where and where[k] != where["pus"]:
                self.add(self.file, ["processes", where[k]], "runs %s without pus; expected %s "
                         "in the process of pus (%s)" % (k, k, where["pus"]))  # fmt: skip
            elif k in where and "pus" not in where:
                self.add(self.file, ["processes", where[k]], "runs %s but no process runs pus; "
                         "expected pus in the same process" % k)  # fmt: skip
        self.where = where

    def _exists(self, rel, path, what, folder=False):
        if not isinstance(rel, str) or not rel:
            return None
        full = os.path.normpath(os.path.join(self.folder, os.path.expanduser(rel)))
        ok = os.path.isdir(full) if folder else os.path.isfile(full)
        if not ok:
            self.add(self.file, path, "%s %s not found; expected %s" % (
                "folder" if folder else "file", short(rel), what))  # fmt: skip
            return None
        return full

    def _paths(self, doc):
        sdb = doc.get("sdb", defaults.top("sdb"))
        self.sdb_file = self._exists(sdb, ["sdb"], "the spacecraft database")
        obcp = doc.get("obcp") if isinstance(doc.get("obcp"), dict) else {}
        self.procedures = self._exists(
            obcp.get("files"), ["obcp", "files"], "the folder of the procedures", folder=True
        )
        frames = doc.get("frames") if isinstance(doc.get("frames"), dict) else {}
        self._exists(frames.get("keys"), ["frames", "keys"], "a key file of obsw frames keygen")
        self._link(frames)

    def _orbit_and_stations(self, doc):
        """The orbit's TLE (checksums, elements SGP4 accepts) agrees with its stated epoch;
        station names are unique."""
        from obsw_host.ops.tle import TleError, format_time, parse, parse_time

        orbit = doc.get("orbit")
        if isinstance(orbit, dict) and not any(
            p.path.startswith("$.orbit") for p in self.problems
        ):
            try:
                tle = parse(orbit["tle"], orbit.get("name"))
                stated = parse_time(orbit["epoch"])
            except TleError as e:
                self.add(self.file, ["orbit"], str(e))
            else:
                if abs((tle.epoch - stated).total_seconds()) > 0.001:
                    self.add(self.file, ["orbit", "epoch"], "%s; expected the TLE's epoch %s"
                             % (orbit["epoch"], format_time(tle.epoch)))  # fmt: skip
        seen = set()
        for i, st in _dicts(doc.get("stations")):
            name = st.get("name")
            if isinstance(name, str) and name in seen:
                self.add(self.file, ["stations", i, "name"], "station %s named twice; expected "
                         "one entry per station" % short(name))  # fmt: skip
            seen.add(name)
        if "stations" in doc and "orbit" not in doc:
            self.add(self.file, ["stations"], "stations without an orbit; expected orbit.tle "
                     "and orbit.epoch to predict their passes")  # fmt: skip

    def _link(self, frames):
        """The TM coding with the frame length: what the coder itself accepts."""
        if any(p.path.startswith("$.frames") for p in self.problems):
            return  # the schema already said what is wrong there
        from obsw_host.frames.coding import LinkSettings

        for path, text in LinkSettings(frames).problems():
            self.add(self.file, path, text)

    # -------------------------------------------------------------------- the database

    def database(self):
        if self.sdb_file is None:
            return None
        f = self.sdb_file
        doc, problems = read_json(f, self.folder)
        self.problems += problems
        if doc is None:
            return None
        self.problems += validate(doc, defaults.SDB_SCHEMA, f)
        if not isinstance(doc, dict):
            return None
        self.sdb_doc = doc
        self._apids(f, doc)
        self._scid(f, doc)
        params = self._parameters(f, doc)
        self._events(f, doc)
        self._housekeeping(f, doc, params)
        self._nodes(f, doc)
        self._functions(f, doc)
        self._services(f, doc)
        self._files(f, doc)
        pos = doc.get("position_scheduling")
        if isinstance(pos, dict) and "parameter" in pos:
            self._ref(f, ["position_scheduling", "parameter"], pos["parameter"], params)
        self._against_components(f, doc)
        return doc

    def _against_components(self, f, doc):
        """The database against the components that serve it (``crosscheck``)."""
        from obsw_host.obc.topology import FRAME_PROCESSOR, OBC_HEALTH

        served = dict(self.interfaces)
        served.update({i.name: i for i in (OBC_HEALTH, FRAME_PROCESSOR)})
        crosscheck.attributes(self, f, doc, served)
        crosscheck.power_cycle(self)

    def _apids(self, f, doc):
        apids = doc.get("apids")
        seen = {}
        for role, apid in apids.items() if isinstance(apids, dict) else ():
            if not _is_int(apid):
                continue
            if apid in seen:
                self.add(f, ["apids", role], "APID %d is also %s's; expected one APID per role"
                         % (apid, seen[apid]))  # fmt: skip
            seen[apid] = role
        pus = self.doc.get("pus") if isinstance(self.doc.get("pus"), dict) else {}
        mission_pus = pus.get("apid")
        if "pus" in self.where and "apid" not in pus:
            if not isinstance(apids, dict) or "pus" not in apids:
                self.add(f, ["apids"], "no APID for pus; expected apids.pus (the PUS "
                         "application process), or pus.apid in the mission file")  # fmt: skip
        elif _is_int(mission_pus) and isinstance(apids, dict) and _is_int(apids.get("pus")):
            if apids["pus"] != mission_pus and 0 <= apids["pus"] <= 0x7FF:
                self.add(self.file, ["pus", "apid"], "APID %d differs from the database's "
                         "apids.pus %d; expected the same APID (or leave pus.apid out)"
                         % (mission_pus, apids["pus"]))  # fmt: skip

    def _scid(self, f, doc):
        """The spacecraft id is named once: the mission file's frames.scid, if given, agrees."""
        mine = self.doc.get("frames") if isinstance(self.doc.get("frames"), dict) else {}
        theirs = doc.get("frames") if isinstance(doc.get("frames"), dict) else {}
        a, b = mine.get("scid"), theirs.get("scid")
        if _is_int(a) and _is_int(b) and a != b and 0 <= b <= 1023:
            self.add(
                self.file,
                ["frames", "scid"],
                "spacecraft id %d differs from the "
                "database's frames.scid %d; expected the same (or leave it out)" % (a, b),
            )

    def _parameters(self, f, doc):
        """Parameter ids and names given twice; returns qualified name and id -> type."""
        by_id = {}
        by_name = {}
        comps = set()
        entries = []
        for ci, comp in _dicts(doc.get("components")):
            cname = comp.get("name")
            if not isinstance(cname, str):
                continue
            if cname in comps:
                self.add(f, ["components", ci, "name"], "component %s declared twice; expected "
                         "each component once" % cname)  # fmt: skip
                continue
            comps.add(cname)
            for ai, a in _dicts(comp.get("attributes")):
                entries.append((["components", ci, "attributes", ai], cname, a, "parameter"))
        for pi, p in _dicts(doc.get("parameters")):
            entries.append((["parameters", pi], None, p, "id"))
        for path, cname, p, id_key in entries:
            name = p.get("name")
            pid = p.get(id_key)
            if not isinstance(name, str):
                continue
            qualified = "%s.%s" % (cname, name) if cname else name
            if qualified in by_name:
                self.add(f, path + ["name"], "parameter %s declared twice; expected each name "
                         "once" % qualified)  # fmt: skip
                continue
            if _is_int(pid) and pid in by_id:
                self.add(f, path + [id_key], "parameter id %d is also %s's; expected each id "
                         "once" % (pid, by_id[pid][0]))  # fmt: skip
                continue
            by_name[qualified] = p.get("type")
            if _is_int(pid):
                by_id[pid] = (qualified, p.get("type"))
            self._values(f, path, p)
        self.components_in_sdb = comps
        return {"names": by_name, "ids": by_id}

    def _values(self, f, path, p):
        """``range``, ``limits``, ``calibration`` and ``default`` of one parameter."""
        t = p.get("type")
        rng = p.get("range")
        bounds = _INT_BOUNDS.get(t) if isinstance(t, str) else None
        numeric = isinstance(t, str) and t in _NUMERIC
        for key in ("range", "limits", "calibration"):
            if key in p and isinstance(t, str) and not numeric:
                self.add(f, path + [key], "a %s for type %s; expected it on numeric types only"
                         % (key, t))  # fmt: skip
                return
        if _pair(rng):
            if rng[0] > rng[1]:
                self.add(f, path + ["range"], "%s has low above high; expected [low, high]"
                         % short(rng))  # fmt: skip
                rng = None
            elif bounds and (rng[0] < bounds[0] or rng[1] > bounds[1]):
                self.add(f, path + ["range"], "%s exceeds type %s; expected within [%d, %d]"
                         % (short(rng), t, bounds[0], bounds[1]))  # fmt: skip
                rng = None
        else:
            rng = None
        limits = p.get("limits")
        if isinstance(limits, dict):
            pairs = {k: v for k, v in limits.items() if k in ("warning", "critical") and _pair(v)}
            bad = False
            for k, v in sorted(pairs.items()):
                if v[0] > v[1]:
                    self.add(f, path + ["limits", k], "%s has low above high; expected "
                             "[low, high]" % short(v))  # fmt: skip
                    bad = True
            w, c = pairs.get("warning"), pairs.get("critical")
            if not bad and w and c and not (c[0] <= w[0] and w[1] <= c[1]):
                self.add(
                    f,
                    path + ["limits"],
                    "critical %s inside warning %s; expected the "
                    "critical limits around the warning ones" % (short(c), short(w)),
                )
            elif not bad and rng:
                for k, v in sorted(pairs.items()):
                    if v[0] < rng[0] or v[1] > rng[1]:
                        self.add(f, path + ["limits", k], "%s outside the range %s; expected "
                                 "limits within the range" % (short(v), short(rng)))  # fmt: skip
                        break
        cal = p.get("calibration")
        if isinstance(cal, dict) and isinstance(cal.get("spline"), list):
            raws = [pt[0] for pt in cal["spline"] if _pair(pt)]
            if any(b <= a for a, b in zip(raws, raws[1:])):
                self.add(f, path + ["calibration", "spline"], "raw values not increasing; "
                         "expected [[raw, eng], ...] with raw strictly increasing")  # fmt: skip
        d = p.get("default")
        if "default" in p and numeric and not _is_num(d):
            self.add(f, path + ["default"], "%s is %s; expected a number of type %s"
                     % (short(d), json_type(d), t))  # fmt: skip
        elif _is_num(d) and rng and not rng[0] <= d <= rng[1]:
            self.add(f, path + ["default"], "%s outside the range %s; expected a value within "
                     "the range" % (short(d), short(rng)))  # fmt: skip

    def _events(self, f, doc):
        by_id = {}
        names = set()
        entries = [(["events", i], None, e) for i, e in _dicts(doc.get("events"))]
        for ci, comp in _dicts(doc.get("components")):
            for ei, e in _dicts(comp.get("events")):
                entries.append((["components", ci, "events", ei], comp.get("name"), e))
        for path, cname, e in entries:
            name, eid = e.get("name"), e.get("id")
            if not isinstance(name, str):
                continue
            qualified = "%s.%s" % (cname, name) if cname else name
            if qualified in names:
                self.add(f, path + ["name"], "event %s declared twice; expected each name once"
                         % qualified)  # fmt: skip
                continue
            names.add(qualified)
            if _is_int(eid):
                if eid in by_id:
                    self.add(f, path + ["id"], "event id %d is also %s's; expected each id once"
                             % (eid, by_id[eid]))  # fmt: skip
                    continue
                by_id[eid] = qualified
            fields = [x.get("name") for _, x in _dicts(e.get("data"))]
            for di, n in enumerate(fields):
                if n in fields[:di]:
                    self.add(f, path + ["data", di, "name"], "field %s given twice; expected "
                             "each field once" % n)  # fmt: skip

    def _ref(self, f, path, ref, params):
        if isinstance(ref, str) and ref not in params["names"]:
            self.add(f, path, "no parameter %s; expected a parameter of the database%s"
                     % (short(ref), did_you_mean(ref, params["names"])))  # fmt: skip
        elif _is_int(ref) and ref not in params["ids"]:
            self.add(f, path, "no parameter id %d; expected the id of a parameter of the "
                     "database" % ref)  # fmt: skip

    def _housekeeping(self, f, doc, params):
        sids = set()
        for i, hk in _dicts(doc.get("housekeeping")):
            sid = hk.get("sid")
            if _is_int(sid):
                if sid in sids:
                    self.add(f, ["housekeeping", i, "sid"], "structure id %d declared twice; "
                             "expected each sid once" % sid)  # fmt: skip
                sids.add(sid)
            refs = hk.get("parameters") if isinstance(hk.get("parameters"), list) else []
            for j, ref in enumerate(refs):
                self._ref(f, ["housekeeping", i, "parameters", j], ref, params)

    def _nodes(self, f, doc):
        folder = os.path.dirname(f)
        nodes = [(["nodes", i], n, f, folder) for i, n in _dicts(doc.get("nodes"))]
        spacecan = self.doc.get("spacecan")
        if isinstance(spacecan, dict) and isinstance(spacecan.get("nodes"), list):
            nodes = [(["spacecan", "nodes", i], n, self.file, self.folder)
                     for i, n in _dicts(spacecan["nodes"])]  # fmt: skip
        names, ids = {}, {}
        self.nodes = {}
        for path, n, where, base in nodes:
            name, nid, rel = n.get("name"), n.get("node_id"), n.get("definition")
            if not isinstance(name, str) or not _is_int(nid) or not isinstance(rel, str):
                continue
            if name in names or nid in ids:
                key, value = ("name", name) if name in names else ("node_id", nid)
                self.add(
                    where,
                    path + [key],
                    "%s %s is also node %s's; expected each node "
                    "name and id once" % (key, short(value), names.get(name) or ids[nid]),
                )
                continue
            names[name], ids[nid] = name, name
            full = os.path.normpath(os.path.join(base, rel))
            if not os.path.isfile(full):
                self.add(where, path + ["definition"], "file %s not found; expected a SpaceCAN "
                         "node definition (nodes/NAME.json)" % short(rel))  # fmt: skip
                continue
            ndoc, problems = read_json(full, self.folder)
            self.problems += problems
            if ndoc is None:
                continue
            try:
                nodedef = NodeDefinition.from_dict(ndoc, nid)
                self.interfaces[name] = equipment_interface(name, nid, nodedef)
            except (NodeDefinitionError, ValueError) as e:
                self.add(full, "$", "%s; expected a SpaceCAN node definition" % e)
                continue
            self.nodes[name] = nid
        pc = self.doc.get("platform", {}).get("power_cycle") if isinstance(
            self.doc.get("platform"), dict) else None  # fmt: skip
        if isinstance(pc, dict) and isinstance(pc.get("component"), str):
            comp = pc["component"]
            usable = len(self.nodes) == len(nodes)  # a node at fault says so itself
            if "spacecan" in self.where and usable and comp not in self.nodes:
                self.add(self.file, ["platform", "power_cycle", "component"], "no node %s; "
                         "expected a SpaceCAN node (%s)%s" % (short(comp), ", ".join(
                             self.nodes) or "none", did_you_mean(comp, self.nodes)))  # fmt: skip

    def _operations(self, doc):
        """Component name -> {operation: parameter names}; operations and their arguments
        declared twice in the database are problems."""
        ops = {}
        for ci, comp in _dicts(doc.get("components")):
            for oi, op in _dicts(comp.get("operations")):
                at = ["components", ci, "operations", oi]
                mine = ops.setdefault(comp.get("name"), {})
                if op.get("name") in mine:
                    self.add(self.sdb_file, at + ["name"], "operation %s declared twice; "
                             "expected each operation once" % short(op.get("name")))  # fmt: skip
                    continue
                args = []
                for ai, a in _dicts(op.get("arguments")):
                    if a.get("name") in args:
                        self.add(
                            self.sdb_file,
                            at + ["arguments", ai, "name"],
                            "argument %s "
                            "given twice; expected each argument once" % short(a["name"]),
                        )
                    args.append(a.get("name"))
                mine[op.get("name")] = args
        for name, itf in self.interfaces.items():
            for op in itf.operations:
                ops.setdefault(name, {})[op.name] = list(op.params)
        return ops

    def _functions(self, f, doc):
        ops = self._operations(doc)
        ids, names = {}, set()
        for i, fn in _dicts(doc.get("functions")):
            fid, name = fn.get("id"), fn.get("name")
            if _is_int(fid):
                if fid in ids:
                    self.add(f, ["functions", i, "id"], "function id %d is also %s's; expected "
                             "each id once" % (fid, ids[fid]))  # fmt: skip
                    continue
                ids[fid] = name
            if not isinstance(name, str) or "." not in name:
                continue
            if name in names:
                self.add(f, ["functions", i, "name"], "function %s declared twice; expected "
                         "each name once" % name)  # fmt: skip
                continue
            names.add(name)
            comp, op = name.split(".", 1)
            if comp in self.unresolved:
                continue
            if comp not in ops:
                self.add(
                    f,
                    ["functions", i, "name"],
                    "no component %s with operations; "
                    "expected a component of mission.json's components, a node, or one "
                    "declaring operations%s" % (comp, did_you_mean(comp, ops)),
                )
                continue
            if op not in ops[comp]:
                self.add(f, ["functions", i, "name"], "%s has no operation %s; expected one of "
                         "%s%s" % (comp, op, ", ".join(sorted(ops[comp])),
                                   did_you_mean(op, ops[comp])))  # fmt: skip
                continue
            aids, anames = set(), set()
            for j, a in _dicts(fn.get("arguments")):
                aid, an = a.get("id"), a.get("name")
                at = ["functions", i, "arguments", j]
                if _is_int(aid) and aid in aids or an in anames:
                    self.add(f, at, "argument %s given twice; expected each id and name once"
                             % short(an))  # fmt: skip
                    continue
                aids.add(aid)
                anames.add(an)
                params = ops[comp][op]
                if isinstance(an, str) and params and an not in params:
                    self.add(
                        f,
                        at + ["name"],
                        "%s takes no argument %s; expected one of %s%s"
                        % (name, an, ", ".join(params), did_you_mean(an, params)),
                    )

    # -- mission services (types 128..255): ids once, operations and events of the component

    def _services(self, f, doc):
        ops = self._operations(doc)
        types, names = {}, set()
        for i, svc in _dicts(doc.get("services")):
            at = ["services", i]
            t, name, comp = svc.get("type"), svc.get("name"), svc.get("component")
            if _is_int(t) and t in types:
                self.add(f, at + ["type"], "service type %d is also %s's; expected each type "
                         "once" % (t, types[t]))  # fmt: skip
            types.setdefault(t, name)
            if name in names:
                self.add(f, at + ["name"], "service %s declared twice; expected each name once"
                         % short(name))  # fmt: skip
            names.add(name)
            subtypes = {}
            for kind in ("requests", "reports"):
                for j, m in _dicts(svc.get(kind)):
                    sub = m.get("subtype")
                    if _is_int(sub) and sub in subtypes:
                        self.add(f, at + [kind, j, "subtype"], "subtype %d is also %s's; "
                                 "expected each subtype of a service once, requests and "
                                 "reports together" % (sub, subtypes[sub]))  # fmt: skip
                    subtypes.setdefault(sub, m.get("name"))
            reports = [m.get("subtype") for _, m in _dicts(svc.get("reports"))]
            for j, r in _dicts(svc.get("requests")):
                if "report" in r and r["report"] not in reports:
                    self.add(f, at + ["requests", j, "report"], "no report subtype %s in "
                             "service %s; expected one of %s" % (r["report"], short(name),
                             ", ".join(str(x) for x in reports) or "none"))  # fmt: skip
            if isinstance(comp, str) and comp not in self.unresolved:
                self._service_component(f, at, svc, comp, ops)

    def _service_component(self, f, at, svc, comp, ops):
        if comp not in ops:
            self.add(f, at + ["component"], "no component %s with operations; expected a "
                     "component of mission.json's components, a node, or one declaring "
                     "operations%s" % (comp, did_you_mean(comp, ops)))  # fmt: skip
            return
        for j, r in _dicts(svc.get("requests")):
            op = r.get("operation")
            if not isinstance(op, str):
                continue
            if op not in ops[comp]:
                self.add(f, at + ["requests", j, "operation"], "%s has no operation %s; "
                         "expected one of %s%s" % (comp, op, ", ".join(sorted(ops[comp])),
                                                   did_you_mean(op, ops[comp])))  # fmt: skip
                continue
            params = ops[comp][op]
            given = [a.get("name") for _, a in _dicts(r.get("arguments"))]
            if params is not None and given != list(params):
                self.add(f, at + ["requests", j, "arguments"], "%s.%s takes (%s); expected the "
                         "request's arguments in that order, got (%s)" % (comp, op,
                         ", ".join(params), ", ".join(str(g) for g in given)))  # fmt: skip
        itf = self.interfaces.get(comp)
        events = [e.name for e in itf.events] if itf is not None else None
        for j, r in _dicts(svc.get("reports")):
            ev = r.get("event")
            if isinstance(ev, str) and events is not None and ev not in events:
                self.add(f, at + ["reports", j, "event"], "%s has no event %s; expected one "
                         "of %s%s" % (comp, ev, ", ".join(events) or "none",
                                      did_you_mean(ev, events)))  # fmt: skip

    def _files(self, f, doc):
        prefixes, entities, local = {}, {}, None
        for i, fs in _dicts(doc.get("filestores")):
            p, e = fs.get("prefix"), fs.get("entity")
            if isinstance(p, str):
                if p in prefixes:
                    self.add(f, ["filestores", i, "prefix"], "prefix %s declared twice; "
                             "expected each prefix once" % p)  # fmt: skip
                    continue
                prefixes[p] = i
            if _is_int(e):
                if e in entities:
                    self.add(f, ["filestores", i, "entity"], "entity %d is also %s's; expected "
                             "one CFDP entity per filestore" % (e, entities[e]))  # fmt: skip
                    continue
                entities[e] = p
            if fs.get("local") is True:
                if local is not None:
                    self.add(f, ["filestores", i, "local"], "a second local filestore (%s is "
                             "local); expected one" % local)  # fmt: skip
                local = p
        cfdp = self.doc.get("cfdp") if isinstance(self.doc.get("cfdp"), dict) else {}
        peers = cfdp.get("peers") if isinstance(cfdp.get("peers"), dict) else {}
        entities = {fs.get("entity"): fs.get("prefix") for _, fs in _dicts(doc.get("filestores"))}
        for eid in peers:
            if eid.isdigit() and entities and int(eid) not in entities:
                self.add(self.file, ["cfdp", "peers", eid], "entity %s is no filestore's; "
                         "expected one of the database's filestore entities (%s)"
                         % (eid, ", ".join(str(e) for e in entities)))  # fmt: skip
        mids, mnames = set(), set()
        for i, m in _dicts(doc.get("memories")):
            mid, name = m.get("id"), m.get("name")
            if _is_int(mid) and mid in mids or name is not None and name in mnames:
                self.add(f, ["memories", i], "memory %s declared twice; expected each id and "
                         "name once" % short(name if name in mnames else mid))  # fmt: skip
            mids.add(mid)
            mnames.add(name)
            self._objects(f, ["memories", i], m)

    def _objects(self, f, path, m):
        """Objects of a memory area: ids once, each within the area."""
        size = m.get("size") if _is_int(m.get("size")) else None
        ids = set()
        for j, o in _dicts(m.get("objects")):
            oid, off, n = o.get("id"), o.get("offset", 0), o.get("size")
            at = path + ["objects", j]
            if _is_int(oid) and oid in ids:
                self.add(f, at + ["id"], "object %d declared twice; expected each id once" % oid)
                continue
            ids.add(oid)
            if size and _is_int(off) and _is_int(n) and off + n > size:
                self.add(f, at, "octets %d..%d outside the memory's %d; expected offset + size "
                         "within the area" % (off, off + n - 1, size))  # fmt: skip

    # -------------------------------------------------------------------- procedures

    def procedures_of(self, sdb):
        if self.procedures is None:
            return
        catalog = Catalog(sdb, list(self.interfaces.values()))
        resolver = _Resolver(catalog)
        for path in sorted(glob.glob(os.path.join(self.procedures, "*.plt"))):
            try:
                text = read_text(path, MAX_PROCEDURE, self.folder)
                load_procedure(text, resolver)
            except OSError as e:
                self.add(path, "line 1", "cannot read (%s); expected a PLUTO procedure"
                         % e.strerror)  # fmt: skip
            except UnicodeDecodeError as e:
                self.add(path, "line 1", "not UTF-8 text (%s); expected a PLUTO procedure" % e)
            except PlutoError as e:
                for x in getattr(e, "errors", None) or [e]:
                    self.add(path, "line %d column %d" % (x.line, x.col),
                             "%s: %s" % (x.kind, x.msg))  # fmt: skip


class _Resolver:
    """The PLUTO checker's questions answered from the database and the components."""

    def __init__(self, catalog):
        self.catalog = catalog

    def describe(self, path):
        e = self.catalog.find(path)
        if e is None:
            return None
        if e[KIND] == "parameter":
            return ("parameter", e[CODE] or "?", e[UNIT])
        return (e[KIND], None, None)


def _once(problems):
    """``problems`` without repeats (a file two entries name is checked once)."""
    seen = set()
    return [p for p in problems if not (p in seen or seen.add(p))]


def check(mission_file):
    """(Mission or None, problems) of the mission whose file is ``mission_file``."""
    c = _Checker(mission_file)
    if c.mission() is None:
        return None, c.problems
    c.database()
    if c.problems:
        return None, _once(c.problems)
    try:  # what the OBC itself will read: the net under the checks above
        config = MissionConfig(c.doc, mission_file)
        sdb = sdb_module.load(c.sdb_file)
    except (ConfigError, sdb_module.SdbError) as e:
        c.add(c.sdb_file if isinstance(e, sdb_module.SdbError) else c.file, "$", str(e))
        return None, c.problems
    crosscheck.monitoring(c, sdb)
    crosscheck.housekeeping(c, sdb)
    crosscheck.defaults(c, sdb)
    c.procedures_of(sdb)
    if c.problems:
        return None, c.problems
    return Mission(config, sdb, c.interfaces), []


def load(path=None):
    """The checked ``Mission`` at ``path`` (see ``locate``); ``MissionError`` lists problems."""
    mission, problems = check(locate(path))
    if problems:
        raise MissionError(problems)
    return mission
