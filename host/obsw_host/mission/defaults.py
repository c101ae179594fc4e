"""The shipped JSON Schemas and their ``default`` annotations, as an editor shows them.

``section("platform")`` is ``{"heartbeat": 0.5, ...}``; a test keeps these equal to what the
OBC uses for a key the mission file leaves out (``obsw_host.obc.defaults``).
"""

import json
import os

SCHEMA_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "schema")
MISSION_SCHEMA = os.path.join(SCHEMA_DIR, "mission.schema.json")
SDB_SCHEMA = os.path.join(SCHEMA_DIR, "sdb.schema.json")
MISSION_FILE = "mission.json"  # the mission file's name in a mission folder
FORMAT = 2  # the mission file format this version writes and reads

_cache = {}


def schema(path):
    """The JSON Schema at ``path`` (parsed once per process)."""
    s = _cache.get(path)
    if s is None:
        with open(path, encoding="utf-8") as f:
            s = _cache[path] = json.load(f)
    return s


def _resolve(root, node):
    while "$ref" in node:
        node = root["$defs"][node["$ref"].rsplit("/", 1)[1]]
    return node


def section(name, path=MISSION_SCHEMA):
    """Defaults of the keys of top-level object ``name`` (a fresh dict)."""
    root = schema(path)
    props = _resolve(root, root["properties"][name]).get("properties", {})
    out = {}
    for key, node in props.items():
        node = _resolve(root, node) if "default" not in node else node
        if "default" in node:
            out[key] = json.loads(json.dumps(node["default"]))  # a copy callers may change
    return out


def top(key, path=MISSION_SCHEMA):
    """The default of top-level key ``key`` (None: no default)."""
    return schema(path)["properties"][key].get("default")
