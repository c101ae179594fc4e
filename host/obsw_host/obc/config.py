"""The mission configuration as the OBC processes read it (kept here for its importers; the
mission folder, its checks and its defaults live in ``obsw_host.mission``)."""

from obsw_host.mission import locate
from obsw_host.mission.config import (  # noqa: F401 (re-exported)
    KINDS,
    WITH_PUS,
    ConfigError,
    MissionConfig,
    parse_json,
    read,
)


def load(path=None):
    """The configuration of mission ``path`` (a folder or its file), else the one ``locate``
    finds ($OBSW_MISSION, a mission.json here or above); never the sample by default."""
    return read(locate(path))
