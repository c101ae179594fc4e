"""The sample spacecraft shipped with the product: its database, loaded by name."""

import os

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data")
SDB_PATH = os.path.join(DATA, "sdb.json")
CPDU_NODE_PATH = os.path.join(DATA, "cpdu_node.json")


def load_sdb(path=None):
    """The spacecraft database at ``path`` (default: the sample); errors say which file."""
    from obsw.pus import sdb as sdb_module

    path = path or SDB_PATH
    try:
        return sdb_module.load(path)
    except sdb_module.SdbError as e:
        raise sdb_module.SdbError("%s: %s" % (path, e)) from None
