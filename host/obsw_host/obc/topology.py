"""The composition root: every unit of the OBC, the process that runs it, and its connections.

``Topology(config)`` is built once from the mission configuration and read by everyone who
needs to know the shape of the OBC, instead of their reading each other: the platform
manager (which processes to start, the health interface of each, the CPDU to power-cycle),
each OBC process (which units to build, ``obsw_host.obc.registry``), the PUS unit (its
service table, the interfaces its OBCP engine may use) and the plug-in components
(``obsw_host.obc.plugins``). The spacecraft database is read once, here, when first needed.

The interfaces that join the processes are named here too: ``Process_<name>`` (each
process's heartbeat) and ``Platform`` (the platform manager's events, raised by the PUS
process). ``describe()`` gives the whole topology as data (``obsw obc config`` prints it).
"""

import os

from obsw.il.interface import DATA, Attribute, Interface, Operation

from obsw_host.mission import defaults
from obsw_host.mission.config import ConfigError
from obsw_host.mission.ids import MissionIds
from obsw_host.obc import plugins
from obsw_host.obc.onboard_time import ONBOARD_TIME
from obsw_host.obc.passes import PASSES
from obsw_host.obc.registry import WITH_PUS
from obsw_host.update.component import SOFTWARE

HEALTH_BASE = 0x7F00  # interface ids of the processes' health components: base + index
PLATFORM = Interface(
    "Platform",
    0x7EFF,
    [
        Operation("report", 1, ("event", "process", "pid"), description="raise a platform event"),
        Operation("status", 2, ("restarts", "watchdog"), description="supervision figures"),
    ],
    description="the platform manager's events, raised by the PUS process",
)
PLATFORM_EVENTS = ("started", "died", "restarted", "power_cycle", "stopped")
FRAME_PROCESSOR = Interface(
    "FrameProcessor",
    0x7E10,
    [
        Attribute("uart_a_dropped", 1, DATA, type="u32", description="TM frames UART A lost"),
        Attribute("uart_b_dropped", 2, DATA, type="u32", description="TM frames UART B lost"),
    ],
    description="the frame processor's counters",
)
OBC_HEALTH = Interface(
    "Obc",
    0x7E20,
    [
        Attribute("cpu_load", 1, DATA, type="f32", unit="%", description="CPU busy, all cores"),
        Attribute("memory_used", 2, DATA, type="f32", unit="%", description="RAM not available"),
        Attribute("disk_used", 3, DATA, type="f32", unit="%", description="state file system"),
        Attribute("temperature", 4, DATA, type="f32", unit="degC", description="SoC sensor"),
        Attribute("uptime", 5, DATA, type="u32", unit="s", description="since the OBC booted"),
        Attribute("restarts", 6, DATA, type="u32", description="process restarts since start"),
        Attribute("watchdog", 7, DATA, type="u8", description="hardware watchdog state"),
    ],
    description="the OBC's own health (obsw_host.obc.health), published by the PUS process",
)


def health_interface(name, index):
    """The interface of process ``name``'s health component (``index``: its place)."""
    return Interface(
        "Process_" + name,
        HEALTH_BASE + index,
        [Operation("beat", 1, (), description="pid and beats; HUNG if stuck")],
        description="heartbeat of OBC process %s" % name,
    )


class ProcessPlan:
    """One process of the topology: its built-in unit kinds and its plug-in components."""

    def __init__(self, name, index, kinds, components):
        self.name = name
        self.index = index
        self.kinds = [k for k in kinds if k not in components]
        self.components = [components[k] for k in kinds if k in components]
        self.health = health_interface(name, index)

    def __repr__(self):
        return "ProcessPlan(%s: %s)" % (self.name, ", ".join(u for u, _ in self.units()))

    def units(self):
        """``(label, kind)`` of the units this process builds, in start order: the PUS unit
        (which provides the process's components itself), else one unit for the components,
        then the SpaceCAN master and the frame processor."""
        out = []
        if "pus" in self.kinds:
            out.append(("pus", "pus"))
        elif self.components:
            out.append(("components", "component"))
        for kind in ("spacecan", "frames"):
            if kind in self.kinds:
                out.append((kind, kind))
        return out


class Topology:
    """The OBC of one mission configuration (see the module text)."""

    def __init__(self, config, sdb=None):
        self.config = config
        self._sdb = sdb
        self._ids = None
        self._equipments = None
        self.components = plugins.components(config)
        self.processes = [
            ProcessPlan(name, i, kinds, self.components)
            for i, (name, kinds) in enumerate(config.processes.items())
        ]

    def __repr__(self):
        return "Topology(%s: %s)" % (self.config.name, self.processes)

    # -------------------------------------------------------------------------- shape

    def process(self, name):
        for p in self.processes:
            if p.name == name:
                return p
        raise ConfigError("--process", "no process %r in %s (one of %s)" % (
            name, self.config.path, ", ".join(p.name for p in self.processes)))  # fmt: skip

    def process_of(self, name):
        """The process that runs kind or component ``name`` (None if none does)."""
        for p in self.processes:
            if name in p.kinds or any(c.name == name for c in p.components):
                return p
        return None

    def runs(self, name):
        return self.process_of(name) is not None

    def section(self, name):
        """The mission file's section ``name`` over its defaults (``mission.defaults``)."""
        return defaults.section(self.config, name)

    def check(self):
        """Import every component module and find its interface and class; ``PluginError``
        names the mission file's entry if one cannot be used. Returns self."""
        for c in self.components.values():
            if self.runs(c.name):
                c.check()
        return self

    # -------------------------------------------------------------------------- data

    @property
    def sdb(self):
        """The spacecraft database, read once."""
        if self._sdb is None:
            from obsw_host.sample import load_sdb

            self._sdb = load_sdb(self.config.sdb_path)
        return self._sdb

    @property
    def ids(self):
        """Every id and port of the mission (``obsw_host.mission.ids.MissionIds``), read once."""
        if self._ids is None:
            self._ids = MissionIds(self.sdb, self.config.sdb_path, self.config)
        return self._ids

    def pus_apid(self):
        return self.ids.pus_apid

    def pus_port(self):
        return self.ids.ports.pus

    def equipments(self):
        """The SpaceCAN equipment: the mission's ``spacecan.nodes`` if it lists any, else the
        spacecraft database's ``nodes`` (built once)."""
        if self._equipments is None:
            from obsw.pus.sdb import NodeDef
            from obsw.spacecan.equipment import Equipment
            from obsw.spacecan.nodedef import NodeDefinition

            listed = self.config.section("spacecan").get("nodes")
            if listed:
                nodes = [
                    NodeDef(n["name"], int(n["node_id"]), self.config.resolve(n["definition"]))
                    for n in listed
                ]
            else:
                nodes = list(self.sdb.nodes.values())
            self._equipments = [
                Equipment(n.name, n.node_id, NodeDefinition.load(n.definition, n.node_id))
                for n in nodes
            ]
        return self._equipments

    def equipment_interfaces(self):
        """The interfaces of the SpaceCAN equipment components."""
        return [eq.interface for eq in self.equipments()] if self.runs("spacecan") else []

    def component_interfaces(self):
        """The interfaces of the mission's plug-in components that some process runs."""
        return [c.interface() for c in self.components.values() if self.runs(c.name)]

    def interfaces(self):
        """Every component interface of the OBC, wherever it runs (the OBCP engine's)."""
        frames = [FRAME_PROCESSOR] if self.runs("frames") else []
        pus = [ONBOARD_TIME, SOFTWARE, PASSES] if self.runs("pus") else []  # the PUS process's own
        return self.component_interfaces() + self.equipment_interfaces() + frames + pus

    def describe(self):
        """The topology as data: processes, their units and components, and connections."""
        out = {"processes": {}, "components": {}}
        for p in self.processes:
            out["processes"][p.name] = {
                "units": [label for label, _ in p.units()],
                "with_pus": [k for k in WITH_PUS if k in p.kinds],
                "components": [c.name for c in p.components],
                "health": p.health.name,
            }
        for c in self.components.values():
            out["components"][c.name] = {
                "module": c.module_ref,
                "class": c.class_name,
                "options": c.options,
                "process": getattr(self.process_of(c.name), "name", None),  # None: not run
            }
        out["interaction_layer"] = os.path.abspath(self.config.il_directory)
        return out
