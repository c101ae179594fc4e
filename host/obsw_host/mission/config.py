"""The mission file as the OBC reads it: ``MissionConfig`` (vetted by ``mission.check``).

Every path in it is relative to the file. Top level (see ``schema/mission.schema.json`` and
docs/mission.md for every key): ``format`` (2), ``name``, ``sdb`` (default ``sdb.json``),
``host``, ``state``, ``il_directory``, ``ports``, ``processes`` (process name -> built-in kinds
and component names), ``components`` (the mission's plug-ins), one section per built-in kind
(``pus``, ``cfdp``, ``obcp``, ``spacecan``, ``frames``) and ``platform``. A key left out takes
the schema's default (``obsw_host.mission.defaults``).
"""

import json
import os

from obsw_host.mission import defaults

KINDS = ("pus", "cfdp", "obcp", "spacecan", "frames")  # the built-in component kinds
WITH_PUS = ("cfdp", "obcp")  # kinds that run in the process of pus (services 23 and 18)
SECTIONS = KINDS + ("platform",)


class ConfigError(ValueError):
    """A mission configuration that cannot be used: ``key`` says where."""

    def __init__(self, key, message):
        super().__init__("%s: %s" % (key, message))
        self.key = key


def parse_json(text, where):
    """The one place a configuration's JSON is parsed."""
    try:
        return json.loads(text)
    except ValueError as e:
        raise ConfigError(where, "not valid JSON (%s)" % e) from None


class MissionConfig:
    """A loaded mission file (see the module text); ``check`` has vetted it before a start."""

    def __init__(self, doc, path):
        if not isinstance(doc, dict):
            raise ConfigError(path, "expected a JSON object")
        self.doc = doc
        self.path = os.path.abspath(path)
        self.dir = os.path.dirname(self.path)
        self.format = doc.get("format", 1)
        self.name = str(doc.get("name", os.path.splitext(os.path.basename(path))[0]))
        self.host = str(doc.get("host", defaults.top("host")))
        sdb = doc.get("sdb", defaults.top("sdb"))
        if not isinstance(sdb, str) or not sdb:
            raise ConfigError("sdb", "expected a path, got %r" % (sdb,))
        self.sdb_path = self.resolve(sdb)
        self.state = self.resolve(doc.get("state", "state"))
        il = doc.get("il_directory")
        self.il_directory = self.resolve(il) if il else os.path.join(self.state, "il")
        self.components = self._components()
        self.processes = self._processes()
        self.platform = self.section("platform")

    def _components(self):
        comps = self.doc.get("components", {})
        if not isinstance(comps, dict):
            raise ConfigError("components", "expected component name -> {module, class}")
        return {name: dict(spec) for name, spec in comps.items()}

    def _processes(self):
        procs = self.doc.get("processes")
        if not isinstance(procs, dict) or not procs:
            raise ConfigError("processes", "expected process name -> [component kinds]")
        where = {}
        for name, kinds in procs.items():
            if not isinstance(kinds, list) or not kinds:
                raise ConfigError("processes.%s" % name, "expected a list of component kinds")
            for k in kinds:
                if k not in KINDS and k not in self.components:
                    raise ConfigError(
                        "processes.%s" % name,
                        "unknown component %r (one of %s or a name of 'components')"
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
        """The options of ``kind`` with the schema's defaults for the keys left out."""
        s = self.doc.get(kind, {})
        if not isinstance(s, dict):
            raise ConfigError(kind, "expected an object")
        out = defaults.section(kind) if kind in SECTIONS else {}
        out.update(s)
        return out

    def runs(self, kind):
        """True if some process runs component ``kind`` (a built-in kind or a plug-in)."""
        return kind in self.where

    def process_of(self, kind):
        return self.where.get(kind)

    def plugins(self, kinds=None):
        """Names of the mission's components run by ``kinds`` (default: by any process)."""
        names = self.where if kinds is None else kinds
        return [k for k in names if k in self.components]


def read(path):
    """The ``MissionConfig`` of mission file ``path`` (no checks beyond its shape)."""
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        raise ConfigError(path, "cannot read (%s)" % e.strerror) from None
    return MissionConfig(parse_json(text, path), path)
