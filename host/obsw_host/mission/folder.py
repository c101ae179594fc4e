"""Finding a mission: ``locate(path)`` names the mission file of a folder, a file,
``$OBSW_MISSION`` or the nearest ``mission.json``; the sample is never used silently."""

import os

from obsw_host.errors import UserError
from obsw_host.mission.defaults import MISSION_FILE

ENV = "OBSW_MISSION"


def _file_of(path, source):
    path = os.path.abspath(os.path.expanduser(path))
    if os.path.isdir(path):
        f = os.path.join(path, MISSION_FILE)
        if not os.path.isfile(f):
            raise UserError(
                "%s%s has no %s" % (source, path, MISSION_FILE),
                expected="a mission folder (`obsw mission new NAME` writes one)",
            )
        return f
    if not os.path.isfile(path):
        raise UserError("%s%s: no such file or folder" % (source, path),
                        expected="a mission folder or its mission file")  # fmt: skip
    return path


def locate(path=None):
    """The mission file of ``path`` (folder or file), $OBSW_MISSION, or the nearest
    ``mission.json`` from the working folder up; else a one-line ``UserError``."""
    if path:
        return _file_of(path, "")
    env = os.environ.get(ENV)
    if env:
        return _file_of(env, "$%s: " % ENV)
    folder = os.getcwd()
    while True:
        f = os.path.join(folder, MISSION_FILE)
        if os.path.isfile(f):
            return f
        parent = os.path.dirname(folder)
        if parent == folder:
            break
        folder = parent
    raise UserError(
        "no mission named",
        expected="a mission folder: give DIR (or --mission DIR), set $%s, or work in a folder "
        "with a %s (`obsw mission new NAME` writes one)" % (ENV, MISSION_FILE),
    )
