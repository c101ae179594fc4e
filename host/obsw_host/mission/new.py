"""``obsw mission new NAME``: a mission folder written from the template the package ships.

The template (``template/``) is a spacecraft with the PUS application process, the CFDP
entity, the OBCP engine and the SpaceCAN master with the reconfiguration module's CPDU (nodes
10 and 11, simulated): it passes ``obsw mission check`` and runs under ``obsw obc serve``.
The new folder's files name the shipped JSON Schemas in ``$schema`` for editors.
"""

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
    """How ``folder``'s files name ``schema``: relative when it is nearby (a source tree),
    else its absolute path (an installed package)."""
    rel = os.path.relpath(schema, folder)
    return rel if not rel.startswith("../../..") else schema


def write(name, folder):
    """Write mission ``name`` into ``folder`` (new or empty); returns the folder."""
    if not NAME.match(name):
        raise UserError("mission name %r is not usable" % name,
                        expected="letters, digits, '_', '.' and '-' (up to 64)")  # fmt: skip
    folder = os.path.abspath(folder)
    if os.path.exists(folder) and (not os.path.isdir(folder) or os.listdir(folder)):
        raise UserError("%s already exists" % folder, expected="a new or empty folder")
    shutil.copytree(TEMPLATE_DIR, folder, dirs_exist_ok=True,
                    ignore=shutil.ignore_patterns("__pycache__"))  # fmt: skip
    _rewrite(os.path.join(folder, MISSION_FILE),
             {"$schema": _schema_ref(folder, MISSION_SCHEMA), "name": name})  # fmt: skip
    _rewrite(os.path.join(folder, "sdb.json"),
             {"$schema": _schema_ref(folder, SDB_SCHEMA), "mission": name})  # fmt: skip
    return folder
