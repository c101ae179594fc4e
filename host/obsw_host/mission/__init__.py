"""The mission folder: the unit a team writes and versions, checked as a whole before a start.

A folder holds ``mission.json`` (the mission file: processes, units, links, ports, state),
``sdb.json`` (the spacecraft database), ``nodes/*.json`` (SpaceCAN node definitions),
``procedures/*.plt`` (PLUTO) and ``components/*.py`` (the mission's own components).

``locate(path)`` finds the mission file: ``path`` (a folder or a file), else ``$OBSW_MISSION``,
else a ``mission.json`` in the working folder or a parent; the sample is never used silently.
``load(path)`` returns the checked ``Mission`` (its ``MissionConfig`` and its database, read
once) or raises ``MissionError`` listing every problem, one line each.
"""

import os

from obsw_host.errors import UserError
from obsw_host.mission.defaults import MISSION_FILE
from obsw_host.mission.errors import MissionError, Problem  # noqa: F401 (public names)

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


def load(path=None):
    """The checked ``Mission`` at ``path`` (see ``locate``); ``MissionError`` lists problems."""
    # imported here: the checker pulls in jsonschema and the PLUTO checker, which the OBC's
    # child processes (they read a mission already checked) should not pay for at start
    from obsw_host.mission.check import check

    mission, problems = check(locate(path))
    if problems:
        raise MissionError(problems)
    return mission
