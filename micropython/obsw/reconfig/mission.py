"""The mission's ids on a reconfiguration board: ``mission.json`` on its filesystem.

The host writes the file from the mission (``obsw_host.reconfig.board_file``) and it is copied
to each board's flash beside ``tc.keys``; ``load`` turns it into ``ReconfigApp`` options:

    {"scid": 66, "nodes": [10, 11], "essential_map": 63, "hptm_vc": 6}

``nodes`` are the SpaceCAN node ids of the nominal and the redundant controller; an optional
``recovery`` object holds the autonomous recovery's thresholds (``obsw.reconfig.recovery``:
the keys of its ``DEFAULTS``, each optional), and ``name`` the mission's name, which the
packages that update the module's application must carry (``obsw.reconfig.appslot``). A board
without the file runs with the application's built-in ids and says so once (``load`` returns
None); a file that is there but wrong raises ``MissionFileError`` naming the key.
"""

import json

from obsw.reconfig.recovery import DEFAULTS as RECOVERY_DEFAULTS

FILE = "mission.json"
KEYS = ("scid", "nodes", "essential_map", "hptm_vc")
OPTIONAL = ("recovery", "name")  # name: the mission's, which update packages must name


class MissionFileError(ValueError):
    """A board mission file with a missing or unusable entry."""

    def __init__(self, key, message):
        super().__init__("%s: %s: %s" % (FILE, key, message))
        self.key = key


def _int(doc, key, low, high):
    value = doc.get(key)
    if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
        raise MissionFileError(key, "expected an integer %d-%d, got %r" % (low, high, value))
    return value


def parse(doc):
    """``ReconfigApp`` keyword options from a parsed mission file."""
    if not isinstance(doc, dict):
        raise MissionFileError("", "expected a JSON object")
    for key in doc:
        if key not in KEYS and key not in OPTIONAL:
            raise MissionFileError(key, "unknown key (one of %s)" % ", ".join(KEYS + OPTIONAL))
    for key in KEYS:
        if key not in doc:
            raise MissionFileError(key, "missing")
    nodes = doc["nodes"]
    if not isinstance(nodes, list) or len(nodes) != 2:
        raise MissionFileError("nodes", "expected [nominal node id, redundant node id]")
    for n in nodes:
        if (
            isinstance(n, bool)
            or not isinstance(n, int)
            or not 1 <= n <= 127
            or nodes[0] == nodes[1]
        ):
            raise MissionFileError(
                "nodes", "expected two different node ids 1-127, got %r" % nodes
            )
    out = {
        "scid": _int(doc, "scid", 0, 1023),
        "node_ids": (nodes[0], nodes[1]),
        "essential_map": _int(doc, "essential_map", 0, 63),
        "hptm_vc": _int(doc, "hptm_vc", 0, 6),
    }
    if "recovery" in doc:
        out["recovery"] = _recovery(doc["recovery"])
    if not isinstance(doc.get("name", ""), str):
        raise MissionFileError("name", "expected the mission's name")
    return out


def _recovery(doc):
    """The recovery thresholds, checked key by key."""
    if not isinstance(doc, dict):
        raise MissionFileError("recovery", "expected a JSON object")
    for key in doc:
        if key not in RECOVERY_DEFAULTS:
            raise MissionFileError("recovery." + key, "unknown key")
        v = doc[key]
        if key == "enabled":
            ok = isinstance(v, bool)
        elif key == "lines":
            ok = isinstance(v, list) and len(v) == 2 and v[0] != v[1]
            ok = ok and all(isinstance(n, int) and not isinstance(n, bool) for n in v)
            ok = ok and all(0 <= n < 12 for n in v)
        else:
            ok = isinstance(v, (int, float)) and not isinstance(v, bool) and v > 0
        if not ok:
            raise MissionFileError("recovery." + key, "unusable value %r" % (v,))
    return doc


def load(path=FILE):
    """The options of the mission file at ``path``; None when there is none."""
    try:
        f = open(path)
    except OSError:
        return None
    try:
        text = f.read()
    finally:
        f.close()
    try:
        doc = json.loads(text)
    except ValueError:
        raise MissionFileError("", "not valid JSON") from None
    return parse(doc)
