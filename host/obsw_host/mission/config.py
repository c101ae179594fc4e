"""The mission configuration: one JSON file that says what the onboard computer runs.

Every path in it is relative to the file. Top level:

- ``format``: 2 (``obsw mission upgrade`` converts older files); ``name``: the spacecraft's
  name; ``sdb``: the spacecraft database (default ``sdb.json``); ``host``: the address
  every UDP service binds (default loopback, ``obsw_host.net.DEFAULT_HOST``); ``state``: the
  folder for the context store, the onboard filestore and the packet stores;
  ``il_directory``: the interaction layer's name directory (default: a folder under ``state``).
- ``processes``: process name -> list of component kinds it runs (``pus``, ``cfdp``,
  ``obcp``, ``spacecan``, ``frames``) and names of the mission's ``components`` (plug-ins,
  ``obsw_host.obc.plugins``); one process or several. ``cfdp`` and ``obcp`` run with ``pus``
  (services 23 and 18 use them directly).
- ``components``: component name -> ``{"module", "class", "options"}`` (``obsw_host.obc.plugins``).
- one section per component kind with its options (``pus``, ``cfdp``, ``obcp``, ``spacecan``,
  ``frames``), and ``platform`` for the platform manager (heartbeat period, restart deadline,
  failures allowed in a window before the OBC asks to be power-cycled).

``load(path)`` returns a ``MissionConfig`` of the mission ``obsw_host.mission.locate`` finds
(never the sample by default); anything wrong raises ``ConfigError`` naming the key and what
was expected. ``obsw_host.mission.check`` checks the whole mission folder before a start; the
JSON Schema of the file (``obsw_host/mission/schema``) states every key.
"""

import os

from obsw_host.mission.defaults import PLATFORM as _PLATFORM
from obsw_host.mission.errors import ConfigError  # noqa: F401 (raised here, public)
from obsw_host.mission.folder import locate
from obsw_host.net import DEFAULT_HOST
from obsw_host.obc.registry import KINDS, WITH_PUS
from obsw_host.obc.state import default_state

# component kinds that became plug-ins: the kind -> (component name, its entry)
_LEGACY_KINDS = {"solar_panel": ("SolarPanel", {"module": "obsw_host.solar_panel"})}


def parse_json(text, where):
    """The one place a configuration's JSON is parsed."""
    from obsw_host.mission.folder import loads_json

    try:
        return loads_json(text)
    except ValueError as e:
        raise ConfigError(where, "not valid JSON (%s)" % e) from None


class MissionConfig:
    """A loaded mission configuration (see the module text)."""

    def __init__(self, doc, path):
        if not isinstance(doc, dict):
            raise ConfigError(path, "expected a JSON object")
        self.doc = doc
        self.path = os.path.abspath(path)
        self.dir = os.path.dirname(self.path)
        self.format = doc.get("format", 1)
        self.name = str(doc.get("name", os.path.splitext(os.path.basename(path))[0]))
        self.host = str(doc.get("host", DEFAULT_HOST))
        self.sdb_path = self.resolve(self._str("sdb"))
        # a mission file that names no state folder gets the user's state folder of its name,
        # never a folder beside the mission (that may be the source tree)
        self.state = self.resolve(doc["state"]) if "state" in doc else default_state(self.name)
        il = doc.get("il_directory")
        self.il_directory = self.resolve(il) if il else os.path.join(self.state, "il")
        self.processes = self._processes()
        platform = dict(_PLATFORM)
        platform.update(self.section("platform"))
        self.platform = platform

    def _str(self, key):
        v = self.doc.get(key, "sdb.json" if key == "sdb" else None)
        if not isinstance(v, str) or not v:
            raise ConfigError(key, "expected a path, got %r" % (v,))
        return v

    def _legacy(self, procs):
        """Kinds that became plug-ins (``solar_panel``) as the components they are now."""
        components = self.doc.get("components")
        for kinds in procs.values():
            if not isinstance(kinds, list):
                continue
            for i, k in enumerate(kinds):
                if k in _LEGACY_KINDS:
                    component, entry = _LEGACY_KINDS[k]
                    kinds[i] = component
                    if components is None:
                        components = self.doc["components"] = {}
                    if isinstance(components, dict):
                        components.setdefault(component, dict(entry))

    def _processes(self):
        procs = self.doc.get("processes")
        if not isinstance(procs, dict) or not procs:
            raise ConfigError("processes", "expected process name -> [component kinds]")
        self._legacy(procs)
        components = self.doc.get("components", {})
        components = components if isinstance(components, dict) else {}
        where = {}
        for name, kinds in procs.items():
            if not isinstance(kinds, list) or not kinds:
                raise ConfigError("processes.%s" % name, "expected a list of component kinds")
            for k in kinds:
                if k not in KINDS and k not in components:
                    raise ConfigError(
                        "processes.%s" % name,
                        "unknown component %r (a kind of %s, or a name of 'components')"
                        % (k, ", ".join(KINDS)),
                    )
                if k in where:
                    raise ConfigError(
                        "processes.%s" % name, "%r already runs in %r" % (k, where[k])
                    )
                where[k] = name
        for k in WITH_PUS:
            if k in where and where.get("pus") != where[k]:
                raise ConfigError("processes", "%r must run in the process of 'pus'" % k)
        self.where = where
        return {name: list(kinds) for name, kinds in procs.items()}

    def resolve(self, path):
        """``path`` relative to the configuration file (absolute paths stay as they are)."""
        return os.path.normpath(os.path.join(self.dir, os.path.expanduser(str(path))))

    def section(self, kind):
        s = self.doc.get(kind, {})
        if not isinstance(s, dict):
            raise ConfigError(kind, "expected an object")
        return s

    def runs(self, kind):
        """True if some process runs component ``kind``."""
        return kind in self.where

    def process_of(self, kind):
        return self.where.get(kind)


def load(path=None):
    """The configuration of mission ``path`` (a folder or its file), else of the one
    ``obsw_host.mission.locate`` finds ($OBSW_MISSION, a mission.json here or above)."""
    from obsw_host.mission.folder import read_text

    path = locate(path)
    try:
        text = read_text(path, root=os.path.dirname(os.path.abspath(path)))
    except UnicodeDecodeError as e:
        raise ConfigError(path, "not UTF-8 text (%s)" % e) from None
    except OSError as e:
        raise ConfigError(path, "cannot read (%s)" % e.strerror) from None
    return MissionConfig(parse_json(text, path), path)
