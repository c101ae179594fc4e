"""Former home of the spacecraft database: it is ``obsw.pus.sdb`` now (kept for old imports)."""

from obsw.pus.sdb import *  # noqa: F401,F403
from obsw.pus.sdb import SEVERITIES, SEVERITY_NAMES, TYPES, Sdb, SdbError, load, loads  # noqa: F401
