"""The mission folder: the unit a team writes and versions, checked as a whole before a start.

A folder holds ``mission.json`` (the mission file: processes, units, links, ports, state),
``sdb.json`` (the spacecraft database), ``nodes/*.json`` (SpaceCAN node definitions),
``procedures/*.plt`` (PLUTO) and ``components/*.py`` (the mission's own components).

``locate(path)`` finds the mission file: ``path`` (a folder or a file), else ``$OBSW_MISSION``,
else a ``mission.json`` in the working folder or a parent; the sample is never used silently.
``check.load(path)`` returns the checked ``Mission`` (its ``MissionConfig`` and its database, read
once) or raises ``MissionError`` listing every problem, one line each.
"""

from obsw_host.mission.errors import MissionError, Problem  # noqa: F401 (public names)
from obsw_host.mission.folder import ENV, locate  # noqa: F401 (public names)
