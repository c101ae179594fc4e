"""Every id the system uses, read from the mission and named once: ``MissionIds``.

A mission is its mission file (``mission.json``: processes, ports, ...) and the spacecraft
database it names (APIDs, SCID, virtual channels and MAP IDs, CFDP entities, source id, node
ids, the PUS packet layout). ``MissionIds`` reads both and answers each id by name; an id the
mission does not give is a ``MissionError`` naming the file and the key, never a sample value.

    ids = MissionIds.locate("examples/sample")     # a mission folder or a mission file
    ids.apid("pus"), ids.scid, ids.source_id, ids.cfdp_entities, ids.ports.pus

Ground tools take ``--mission DIR`` and ``--sdb FILE`` (an override of the mission's database)
through ``add_arguments`` and ``from_args``.
"""

import argparse
import os

from obsw.frames.tm_mux import TmVirtualChannel
from obsw.frames.tm_plan import TmPlanError, plan_channels, tm_plan
from obsw.pus import sdb as sdb_module
from obsw.pus.config import PusLayoutError, from_sdb

from obsw_host import sample
from obsw_host.errors import UserError
from obsw_host.mission import config as mission_config
from obsw_host.mission.errors import MissionError
from obsw_host.mission.ports import Ports

ESSENTIAL_MAP = 63  # the reconfiguration module's MAP unless the frames plan names one
PACKETS_MAP = 1  # the MAP of ordinary TC packets unless the frames plan names one
FRAMES_KEYS = ("scid", "tc_vc", "maps", "tm_vcs", "cfdp_vc")
MAP_ROLES = ("packets", "essential")
# built-in events, looked up by name in the spacecraft database's events
EVENT_OVERRUN = "pus.cycle_overrun"  # periodic work overran its cycle (service, u8)
EVENT_COPY_COMPLETED = "files.copy_completed"  # service 23 copy done (operation u16, status)
EVENT_COPY_FAILED = "files.copy_failed"  # service 23 copy failed or aborted (same data)
# ports older mission files give in a component's section: port name -> (section, key)
LEGACY_PORTS = {"pus": ("pus", "port"), "cfdp": ("cfdp", "port"), "tm": ("frames", "tm_port")}


def event_id(sdb, name):
    """The id the database gives built-in event ``name``, or None when it declares none."""
    try:
        return sdb.event(name).id
    except KeyError:
        return None


def load_sdb(path):
    """The spacecraft database at ``path``; its errors as one line naming the file (a file
    that cannot be read raises its OSError, which ``obsw`` prints as one line too)."""
    from obsw_host.mission.folder import read_text

    try:
        text = read_text(path)  # bounded: a mission file never runs away
        i = path.rfind("/")
        return sdb_module.loads(text, path[:i] if i > 0 else ("/" if i == 0 else ""))
    except UnicodeDecodeError as e:
        raise UserError("%s: not UTF-8 text (%s)" % (path, e)) from None
    except sdb_module.SdbError as e:
        raise UserError("%s: %s" % (path, e)) from None


class MissionIds:
    """The ids of one mission (see the module text). ``config`` may be None: then only the
    database speaks, and ports come from ``$OBSW_PORT_BASE`` or 5000."""

    def __init__(self, sdb, sdb_path, config=None):
        self.sdb = sdb
        self.sdb_path = sdb_path
        self.sdb_file = os.path.basename(sdb_path) if sdb_path else "spacecraft database"
        self.config = config
        self.mission_file = os.path.basename(config.path) if config else None
        self.ports = Ports.from_section(
            self._port_section(), sdb.apids, where=self._mission_where("ports")
        )
        frames = sdb.frames or {}
        for key in frames:
            if key not in FRAMES_KEYS:
                raise self.error(
                    "frames.%s" % key, "unknown key (one of %s)" % ", ".join(FRAMES_KEYS)
                )

    @classmethod
    def locate(cls, mission=None, sdb=None):
        """The ids of mission folder or file ``mission`` (``obsw_host.mission.folder.locate``),
        with the database at ``sdb`` instead of the mission's when given."""
        config = mission_config.load(mission) if mission is not None or sdb is None else None
        path = sdb or config.sdb_path
        return cls(load_sdb(path), path, config)

    @classmethod
    def sample(cls):
        """The ids of the sample spacecraft shipped with the product (demos, simulations)."""
        return cls.locate(sample.MISSION_PATH)

    def _port_section(self):
        """The mission file's ``ports``, with the ports older mission files give in their
        component sections (``pus.port``, ``cfdp.port``, ``frames.tm_port``)."""
        if self.config is None:
            return None
        section = self.config.doc.get("ports") or {}
        if not isinstance(section, dict):
            raise MissionError.at(self.mission_file, "ports", 'expected an object {"base": N}')
        section = dict(section)
        for name, (kind, key) in LEGACY_PORTS.items():
            value = self.config.section(kind).get(key)
            if value is not None and name not in section:
                section[name] = value
        if "tm" in section and "playback" not in section and isinstance(section["tm"], int):
            section["playback"] = section["tm"] + 1
        return section

    def _mission_where(self, key):
        return "%s: %s" % (self.mission_file, key) if self.mission_file else key

    def error(self, key, message):
        """A MissionError about ``key`` of the spacecraft database."""
        return MissionError.at(self.sdb_file, key, message)

    # -------------------------------------------------------------------------- names

    @property
    def name(self):
        """The mission's name: the mission file's ``name``, else the database's ``mission``."""
        if self.config is not None and self.config.doc.get("name"):
            return str(self.config.doc["name"])
        if self.sdb.mission:
            return str(self.sdb.mission)
        raise self.error("mission", "missing; expected the mission's name")

    # -------------------------------------------------------------------------- packets

    def apid(self, name):
        """The APID the database gives ``name`` (``pus``, ``cfdp``, ``ground``, ...)."""
        try:
            return self.sdb.apids[name]
        except KeyError:
            raise self.error(
                "apids.%s" % name,
                "missing; expected the APID of the %s process (0-2047)" % name,
            ) from None

    @property
    def pus_apid(self):
        """The PUS application process's APID (``apids.pus``; the mission file's ``pus.apid``
        may repeat it, not differ)."""
        apid = self.apid("pus")
        other = self.config.section("pus").get("apid") if self.config else None
        if other is not None and other != apid:
            raise MissionError.at(
                self.mission_file,
                "pus.apid",
                "%r differs from the spacecraft database's apids.pus %d; give it once, in %s"
                % (other, apid, self.sdb_file),
            )
        return apid

    def has_source_id(self):
        return "source_id" in (self.sdb.pus or {}) or "ground" in self.sdb.apids

    @property
    def source_id(self):
        """The source id of the ground's TCs: ``pus.source_id``, else ``apids.ground``."""
        pus = self.sdb.pus or {}
        if "source_id" in pus:
            value = pus["source_id"]
            if isinstance(value, bool) or not isinstance(value, int) or value < 0:
                raise self.error("pus.source_id", "expected an integer >= 0, got %r" % (value,))
            return value
        if "ground" in self.sdb.apids:
            return self.sdb.apids["ground"]
        raise self.error(
            "pus.source_id", "missing (and no apids.ground); expected the ground's source id"
        )

    @property
    def pus_config(self):
        """The PUS packet layout (``obsw.pus.config.PusConfig``) the database declares."""
        try:
            return from_sdb(self.sdb)
        except PusLayoutError as e:
            raise self.error(str(e).split(":")[0], str(e).split(": ", 1)[1]) from None

    def event(self, name):
        """The id of built-in event ``name`` (``files.copy_completed``, ...), which the
        database must declare."""
        found = event_id(self.sdb, name)
        if found is None:
            raise self.error("events", "no event %r; expected the built-in event's id" % name)
        return found

    # -------------------------------------------------------------------------- frames

    @property
    def scid(self):
        """The spacecraft id: the database's ``frames.scid`` (the mission file may repeat it
        in ``frames.scid``, but not differ)."""
        scid = self.sdb.scid
        if scid is None:
            raise self.error("frames.scid", "missing; expected the spacecraft id (0-1023)")
        if not 0 <= scid < 1024:
            raise self.error("frames.scid", "%d is above 1023" % scid)
        other = self.config.section("frames").get("scid") if self.config else None
        if other is not None and other != scid:
            raise MissionError.at(
                self.mission_file,
                "frames.scid",
                "%r differs from the spacecraft database's %d; give it once, in %s"
                % (other, scid, self.sdb_file),
            )
        return scid

    @property
    def tm_vcs(self):
        """The TM virtual channel plan, role -> VC ID (``realtime``, ``playback``,
        ``essential``), from the database's ``frames.tm_vcs``."""
        try:
            return tm_plan(self.sdb.tm_vcs)
        except TmPlanError as e:
            raise self.error("frames.tm_vcs.%s" % e.role, str(e)) from None

    @property
    def playback_vc(self):
        """The packet stores' playback VC: ``frames.tm_vcs.playback`` (the mission file may
        repeat it as ``frames.playback_vc``, not differ)."""
        vc = self.tm_vcs["playback"]
        other = self.config.section("frames").get("playback_vc") if self.config else None
        if other is not None and other != vc:
            raise MissionError.at(
                self.mission_file,
                "frames.playback_vc",
                "%r differs from the spacecraft database's frames.tm_vcs.playback %d; give it "
                "once, in %s" % (other, vc, self.sdb_file),
            )
        return vc

    @property
    def cfdp_vc(self):
        """The TM VC of the CFDP APID's packets (``frames.cfdp_vc``)."""
        vc = (self.sdb.frames or {}).get("cfdp_vc")
        if vc is None:
            raise self.error("frames.cfdp_vc", "missing; expected the TM VC of CFDP packets")
        if isinstance(vc, bool) or not isinstance(vc, int) or not 0 <= vc < 7:
            raise self.error("frames.cfdp_vc", "expected a VC ID 0-6, got %r" % (vc,))
        if vc in self.tm_vcs.values():
            raise self.error("frames.cfdp_vc", "VC %d is already in frames.tm_vcs" % vc)
        return vc

    def has_cfdp_vc(self):
        return (self.sdb.frames or {}).get("cfdp_vc") is not None

    def tm_channels(self, capacity=16384):
        """The TM virtual channels of the plan, and CFDP's when ``frames.cfdp_vc`` names one."""
        channels = plan_channels(self.tm_vcs, capacity)
        if self.has_cfdp_vc():
            channels.append(TmVirtualChannel(self.cfdp_vc, 0, 1 << 20, "cfdp"))
        return channels

    def tm_vc_of_apid(self):
        """APID -> TM VC for the APIDs with a VC of their own (CFDP's, when it has one)."""
        return {self.apid("cfdp"): self.cfdp_vc} if self.has_cfdp_vc() else {}

    @property
    def tc_vc(self):
        """The TC virtual channel of the OBC's packets (``frames.tc_vc``, default 0)."""
        vc = (self.sdb.frames or {}).get("tc_vc", 0)
        if isinstance(vc, bool) or not isinstance(vc, int) or not 0 <= vc < 64:
            raise self.error("frames.tc_vc", "expected a VC ID 0-63, got %r" % (vc,))
        return vc

    @property
    def maps(self):
        """MAP IDs by role: ``packets`` (TC packets, default 1) and ``essential`` (the
        reconfiguration module's high priority commands, default 63)."""
        given = (self.sdb.frames or {}).get("maps") or {}
        maps = {"packets": PACKETS_MAP, "essential": ESSENTIAL_MAP}
        for role, value in given.items():
            if role not in MAP_ROLES:
                raise self.error("frames.maps.%s" % role, "unknown role (packets, essential)")
            if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value < 64:
                raise self.error("frames.maps.%s" % role, "expected a MAP ID 0-63")
            maps[role] = value
        if maps["packets"] == maps["essential"]:
            raise self.error("frames.maps", "packets and essential share MAP %d" % maps["packets"])
        return maps

    # -------------------------------------------------------------------------- files

    @property
    def local_prefix(self):
        """The path prefix of the onboard filestore (``filestores`` entry with ``local``)."""
        prefix = self.sdb.local_filestore
        if prefix is None:
            raise self.error("filestores", "missing; expected the onboard filestore's prefix")
        return prefix

    @property
    def ground_prefix(self):
        """The path prefix of the ground's filestore: the first one that is not onboard."""
        local = self.local_prefix
        for prefix in self.sdb.filestores:
            if prefix != local:
                return prefix
        raise self.error("filestores", "only %s; expected a ground filestore too" % local)

    @property
    def cfdp_entities(self):
        """(onboard entity id, ground entity id) from the database's filestores."""
        fs = self.sdb.filestores
        return fs[self.local_prefix], fs[self.ground_prefix]

    # -------------------------------------------------------------------------- nodes

    def node_id(self, name):
        node = self.sdb.nodes.get(name)
        if node is None:
            raise self.error("nodes", "no node %r" % (name,))
        return node.node_id

    @property
    def reconfig_nodes(self):
        """(nominal, redundant) SpaceCAN node ids of the reconfiguration module: the nodes
        with ``"role": "nominal"`` and ``"role": "redundant"``."""
        found = {}
        for node in self.sdb.nodes.values():
            if node.role is not None:
                if node.role in found:
                    raise self.error("nodes", "two nodes have role %s" % node.role)
                found[node.role] = node.node_id
        for role in ("nominal", "redundant"):
            if role not in found:
                raise self.error(
                    "nodes", 'no node with "role": "%s" (the reconfiguration module\'s)' % role
                )
        return found["nominal"], found["redundant"]

    # -------------------------------------------------------------------------- checking

    def problems(self):
        """Every id the mission's processes need and the mission does not give (or gives
        twice), one line each naming the file and the key: for ``obsw mission check``."""
        runs = self.config.runs if self.config is not None else (lambda kind: True)
        checks = [
            lambda: self.name,
            lambda: self.pus_apid,
            lambda: self.pus_config,
            lambda: self.tm_vcs,
            lambda: self.tc_vc,
            lambda: self.maps,
        ]
        if runs("pus"):
            checks += [lambda: self.local_prefix]
            checks += [
                lambda: self.event(EVENT_COPY_COMPLETED),
                lambda: self.event(EVENT_COPY_FAILED),
            ]
        if runs("cfdp"):
            checks += [lambda: self.apid("cfdp"), lambda: self.cfdp_entities]
        if runs("frames"):
            checks += [lambda: self.scid, lambda: self.playback_vc]
            if self.has_cfdp_vc():
                checks.append(lambda: self.cfdp_vc)
        found = []
        for check in checks:
            try:
                check()
            except UserError as e:
                if str(e) not in found:
                    found.append(str(e))
        return found

    def reconfig_board(self):
        """What the reconfiguration module's boards need to know of the mission, as written to
        their filesystem (``obsw.reconfig.mission``)."""
        nominal, redundant = self.reconfig_nodes
        doc = {
            "scid": self.scid,
            "nodes": [nominal, redundant],
            "essential_map": self.maps["essential"],
            "hptm_vc": self.tm_vcs["essential"],
        }
        if self.config is not None:  # the name update packages for the module must carry
            doc["name"] = self.config.name
        recovery = self.config.doc.get("recovery") if self.config else None
        if recovery is not None:  # the autonomous recovery's thresholds, as the mission says
            doc["recovery"] = dict(recovery)
        return doc


def add_arguments(parser, sdb_help="spacecraft database JSON (overrides the mission's)"):
    """``--mission DIR`` and ``--sdb FILE`` on a ground tool's parser (left out of the
    namespace when not given, so a subcommand's options do not hide its parent's)."""
    parser.add_argument(
        "--mission",
        metavar="DIR",
        default=argparse.SUPPRESS,
        help="mission folder (with mission.json) or mission file (default: $OBSW_MISSION, "
        "else the nearest mission.json from here up)",
    )
    parser.add_argument("--sdb", default=argparse.SUPPRESS, help=sdb_help)


def from_args(args):
    """The ``MissionIds`` of a ground tool's ``--mission`` and ``--sdb``."""
    return MissionIds.locate(getattr(args, "mission", None), getattr(args, "sdb", None))
