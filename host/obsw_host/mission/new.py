"""``obsw mission new NAME``: a mission folder written from the template the package ships.

The template (``template/``) is a spacecraft with the PUS application process, the CFDP
entity, the OBCP engine and the SpaceCAN master with the reconfiguration module's CPDU (nodes
10 and 11, simulated): it passes ``obsw mission check`` and runs under ``obsw obc serve``.
The new folder's files name the shipped JSON Schemas in ``$schema`` for editors.
"""

import binascii
import json
import os
import re
import shutil

from obsw_host.errors import UserError
from obsw_host.mission.defaults import MISSION_FILE, MISSION_SCHEMA, SDB_SCHEMA

TEMPLATE_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "template")
NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$")


def _escaped(key, value):
    """``"key": "value"`` as a replacement text for ``re.sub`` (backslashes doubled)."""
    return ("%s: %s" % (json.dumps(key), json.dumps(value))).replace("\\", "\\\\")


def _rewrite(path, changes):
    with open(path, encoding="utf-8") as f:
        text = f.read()
    for key, value in changes.items():  # keep the template's layout: replace values in place
        text = re.sub(r'"%s": "[^"]*"' % re.escape(key), _escaped(key, value), text, count=1)
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)


def _schema_ref(folder, schema):
    """How ``folder``'s files name ``schema``: a relative path when both are in one source
    tree (``examples/``, ``missions/`` beside ``host/``), else None: an absolute path would
    name one machine's checkout in a folder that is copied to others."""
    rel = os.path.relpath(schema, folder)
    return rel if not rel.startswith("../../..") else None


# A new mission's ids, chosen from its name so that two missions on one machine differ: a
# slot of SLOTS, each with its APIDs (ports are the base + APID), its CFDP entities and its
# spacecraft id; the sample's and aurora's ids are in no slot.
SLOTS = 200
APID_FIRST = 400  # pus = 400 + 8 * slot, frames + 2, cfdp + 4 (its ground port + 5)
SCID_FIRST = 500  # spacecraft id 500 + slot
ENTITY_FIRST = 20  # onboard CFDP entity 20 + 2 * slot, the ground's + 1


def identity(name, slot=None):
    """The ids of new mission ``name`` (``slot``: 0 .. SLOTS - 1, default from the name)."""
    if slot is None:
        slot = binascii.crc32(name.encode()) % SLOTS
    if not 0 <= slot < SLOTS:
        raise UserError("slot %d" % slot, expected="a slot from 0 to %d" % (SLOTS - 1))
    pus = APID_FIRST + 8 * slot
    return {
        "slot": slot,
        "apids": {"pus": pus, "frames": pus + 2, "cfdp": pus + 4, "ground": 0},
        "scid": SCID_FIRST + slot,
        "entities": (ENTITY_FIRST + 2 * slot, ENTITY_FIRST + 2 * slot + 1),
    }


def _set_schema(path, ref):
    """``$schema`` of file ``path`` set to ``ref``, or taken out (None)."""
    with open(path, encoding="utf-8") as f:
        text = f.read()
    if ref is None:
        text = re.sub(r'\n\s*"\$schema": "[^"]*",', "", text, count=1)
    else:
        text = re.sub(r'"\$schema": "[^"]*"', _escaped("$schema", ref), text, count=1)
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)


def _set_ids(folder, name, ids):
    """The template's ids replaced by ``ids`` (``identity``), keeping its layout."""
    path = os.path.join(folder, "sdb.json")
    with open(path, encoding="utf-8") as f:
        text = f.read()
    text = re.sub(r'"apids": \{[^}]*\}', '"apids": %s,\n  "frames": {"scid": %d}' % (
        json.dumps(ids["apids"]), ids["scid"]), text, count=1)  # fmt: skip
    local, ground = ids["entities"]
    text = text.replace('"entity": 2, "local": true', '"entity": %d, "local": true' % local)
    text = text.replace('"prefix": "GROUND", "entity": 1}', '"prefix": "GROUND", "entity": %d}'
                        % ground)  # fmt: skip
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)
    path = os.path.join(folder, MISSION_FILE)
    with open(path, encoding="utf-8") as f:
        text = f.read()
    text = text.replace('"obc-can-a"', json.dumps(name + "-can-a"))
    text = text.replace('"obc-can-b"', json.dumps(name + "-can-b"))
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)


def write(name, folder, slot=None):
    """Write mission ``name`` into ``folder`` (new or empty) with the ids of ``identity(name,
    slot)``; returns (the folder, the ids)."""
    if not NAME.match(name):
        raise UserError("mission name %r is not usable" % name,
                        expected="letters, digits, '_', '.' and '-' (up to 64)")  # fmt: skip
    ids = identity(name, slot)
    folder = os.path.abspath(folder)
    if os.path.exists(folder) and (not os.path.isdir(folder) or os.listdir(folder)):
        raise UserError("%s already exists" % folder, expected="a new or empty folder")
    shutil.copytree(TEMPLATE_DIR, folder, dirs_exist_ok=True,
                    ignore=shutil.ignore_patterns("__pycache__"))  # fmt: skip
    _rewrite(os.path.join(folder, MISSION_FILE), {"name": name})
    _rewrite(os.path.join(folder, "sdb.json"), {"mission": name})
    _set_schema(os.path.join(folder, MISSION_FILE), _schema_ref(folder, MISSION_SCHEMA))
    _set_schema(os.path.join(folder, "sdb.json"), _schema_ref(folder, SDB_SCHEMA))
    _set_ids(folder, name, ids)
    return folder, ids


# the mission file's keys that fix a port by itself (older files): (section, key)
_FIXED_PORTS = (("pus", "port"), ("cfdp", "port"), ("frames", "tm_port"))
FLEET_BASE = 20000  # the port base of a fleet's first mission
FLEET_STEP = 200  # between two missions' bases: each mission's ports stay apart (ids-and-ports)


def _shift_address(text, delta):
    host, sep, port = str(text).rpartition(":")
    return "%s:%d" % (host, int(port) + delta) if sep and port.isdigit() else text


def copy(template, name, folder, scid=None, port_base=None):
    """Write mission ``name`` into ``folder`` as a copy of mission folder ``template`` with its
    name (mission file and database), and with ``scid`` and ``port_base`` when given: the ports
    the mission file fixes by themselves move with the base. Returns the folder."""
    from obsw_host.mission.folder import locate

    if not NAME.match(name):
        raise UserError("mission name %r is not usable" % name,
                        expected="letters, digits, '_', '.' and '-' (up to 64)")  # fmt: skip
    source = os.path.dirname(os.path.abspath(locate(template)))
    folder = os.path.abspath(folder)
    if os.path.exists(folder) and (not os.path.isdir(folder) or os.listdir(folder)):
        raise UserError("%s already exists" % folder, expected="a new or empty folder")
    shutil.copytree(source, folder, dirs_exist_ok=True,
                    ignore=shutil.ignore_patterns("__pycache__"))  # fmt: skip
    mission_path = os.path.join(folder, MISSION_FILE)
    with open(mission_path, encoding="utf-8") as f:
        doc = json.load(f)
    sdb_path = os.path.join(folder, doc.get("sdb", "sdb.json"))
    with open(sdb_path, encoding="utf-8") as f:
        sdb = json.load(f)
    doc["name"] = sdb["mission"] = name
    for d, path, schema in ((doc, mission_path, MISSION_SCHEMA), (sdb, sdb_path, SDB_SCHEMA)):
        if "$schema" in d:
            d["$schema"] = _schema_ref(os.path.dirname(path), schema)
            if d["$schema"] is None:
                del d["$schema"]
    retarget(doc, sdb, scid, port_base)
    for d, path in ((doc, mission_path), (sdb, sdb_path)):
        with open(path, "w", encoding="utf-8") as f:
            json.dump(d, f, indent=2)
            f.write("\n")
    return folder


def retarget(doc, sdb, scid=None, port_base=None):
    """Mission file ``doc`` and database ``sdb`` given spacecraft id ``scid`` and port base
    ``port_base`` (when not None): the ports the mission file fixes by themselves move with
    the base."""
    if scid is not None:
        sdb.setdefault("frames", {})["scid"] = scid
        if "scid" in doc.get("frames", {}):  # a mission file that repeats it
            doc["frames"]["scid"] = scid
    if port_base is not None:
        ports = doc.setdefault("ports", {})
        delta = port_base - ports.get("base", 5000)
        ports["base"] = port_base
        for name_ in [k for k in ports if k != "base"]:
            ports[name_] += delta
        for section, key in _FIXED_PORTS:
            if isinstance(doc.get(section, {}).get(key), int):
                doc[section][key] += delta
        peers = doc.get("cfdp", {}).get("peers") or {}
        for eid in peers:
            peers[eid] = _shift_address(peers[eid], delta)


def fleet(template, prefix, folder, count, scid=None, port_base=FLEET_BASE, step=FLEET_STEP):
    """Write ``count`` missions ``PREFIX-1`` .. ``PREFIX-N`` into ``folder`` from mission folder
    ``template``, each with its own spacecraft id (``scid`` + k, default the template's + k)
    and port base (``port_base`` + k * ``step``). Returns their folders."""
    from obsw_host.mission.ids import MissionIds

    if count < 1:
        raise UserError("--count %d" % count, expected="one mission or more")
    first = MissionIds.locate(template).sdb.scid if scid is None else scid
    first = 0 if first is None else first
    if first + count > 1024:
        raise UserError("spacecraft ids %d to %d" % (first, first + count - 1),
                        expected="ids up to 1023")  # fmt: skip
    if port_base + (count - 1) * step + 5018 > 65535:
        raise UserError("port bases %d to %d" % (port_base, port_base + (count - 1) * step),
                        expected="every port below 65536 (a lower --port-base)")  # fmt: skip
    return [
        copy(template, "%s-%d" % (prefix, k + 1), os.path.join(folder, "%s-%d" % (prefix, k + 1)),
             scid=first + k + (1 if scid is None else 0), port_base=port_base + k * step)
        for k in range(count)
    ]  # fmt: skip


def free_fleet_base(count, step=FLEET_STEP, host="127.0.0.1"):
    """A port base for ``count`` missions ``step`` apart with every port of theirs (the OBC's,
    the gateway's and Yamcs') free on ``host`` now: for tests and benchmarks that run a fleet
    beside other jobs."""
    import socket

    for base in range(30000, 60000 - count * step - 5100, 997):
        ports = set()
        for k in range(count):
            b = base + k * step
            ports |= {b - 1, b, b + 10, b + 100, b + 101, b + 3090} | set(
                range(b + 5015, b + 5019)
            )
        try:
            for port in ports:
                for kind in (socket.SOCK_DGRAM, socket.SOCK_STREAM):
                    s = socket.socket(socket.AF_INET, kind)
                    try:
                        s.bind((host, port))
                    finally:
                        s.close()
        except OSError:
            continue
        return base
    raise RuntimeError("no free port base for %d missions" % count)


def retarget_folder(folder, scid=None, port_base=None):
    """``retarget`` the mission folder ``folder`` in place."""
    mission_path = os.path.join(folder, MISSION_FILE)
    with open(mission_path, encoding="utf-8") as f:
        doc = json.load(f)
    sdb_path = os.path.join(folder, doc.get("sdb", "sdb.json"))
    with open(sdb_path, encoding="utf-8") as f:
        sdb = json.load(f)
    retarget(doc, sdb, scid, port_base)
    for d, path in ((doc, mission_path), (sdb, sdb_path)):
        with open(path, "w", encoding="utf-8") as f:
            json.dump(d, f, indent=2)
            f.write("\n")
