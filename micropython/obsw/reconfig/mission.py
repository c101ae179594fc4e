"""The mission's ids on a reconfiguration board: ``mission.json`` on its filesystem.

The host writes the file from the mission (``obsw_host.reconfig.board_file``) and it is copied
to each board's flash beside ``tc.keys``; ``load`` turns it into ``ReconfigApp`` options:

    {"scid": 66, "nodes": [10, 11], "essential_map": 63, "hptm_vc": 6}

``nodes`` are the SpaceCAN node ids of the nominal and the redundant controller. A board
without the file runs with the application's built-in ids and says so once (``load`` returns
None); a file that is there but wrong raises ``MissionFileError`` naming the key.
"""

import json

FILE = "mission.json"
KEYS = ("scid", "nodes", "essential_map", "hptm_vc")


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
        if key not in KEYS:
            raise MissionFileError(key, "unknown key (one of %s)" % ", ".join(KEYS))
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
    return {
        "scid": _int(doc, "scid", 0, 1023),
        "node_ids": (nodes[0], nodes[1]),
        "essential_map": _int(doc, "essential_map", 0, 63),
        "hptm_vc": _int(doc, "hptm_vc", 0, 6),
    }


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
