"""The sample spacecraft: the mission folder ``examples/sample`` of the source tree, by name.

Nothing uses it by default: callers name it through these constants (tests, demos, examples).
It is not part of an installed package; ``obsw mission new NAME`` writes a mission folder from
the template the package ships (``obsw_host/mission/template``).
"""

import os

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
MISSION_DIR = os.path.join(ROOT, "examples", "sample")
MISSION_PATH = os.path.join(MISSION_DIR, "mission.json")
SDB_PATH = os.path.join(MISSION_DIR, "sdb.json")
CPDU_NODE_PATH = os.path.join(MISSION_DIR, "nodes", "cpdu.json")
PROCEDURES_DIR = os.path.join(MISSION_DIR, "procedures")


def load_sdb(path=None):
    """The spacecraft database at ``path`` (default: the sample's); errors say which file."""
    from obsw.pus import sdb as sdb_module

    from obsw_host.mission.folder import read_text

    path = path or SDB_PATH
    try:
        text = read_text(path)  # bounded: a mission file never runs away
        i = path.rfind("/")
        return sdb_module.loads(text, path[:i] if i > 0 else ("/" if i == 0 else ""))
    except UnicodeDecodeError as e:
        raise sdb_module.SdbError("%s: not UTF-8 text (%s)" % (path, e)) from None
    except sdb_module.SdbError as e:
        raise sdb_module.SdbError("%s: %s" % (path, e)) from None
