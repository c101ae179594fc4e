"""Every port the system uses, named once and counted from one base.

The thesis puts each application process on UDP ``base + APID`` with base 5000; every other
port sits at a fixed offset from the same base, so moving the base moves the whole system
(a second system on one machine, a test):

========================  ======================  ===================================
name                      port (base 5000)        what listens
========================  ======================  ===================================
``for_apid(apid)``        base + APID             an application process (PUS: 5010)
``pus``                   base + apids.pus        the PUS application process
``cfdp``                  base + apids.cfdp       the onboard CFDP entity (5100)
``cfdp_ground``           base + apids.cfdp + 1   the ground CFDP entity (5101)
``tm``                    base - 1                the frame processor's TM input (4999)
``playback``              base                    its playback VC input (TM + 1)
``yamcs_pus``             base + 5015             Yamcs' PUS packet link (10015)
``yamcs_cfdp``            base + 5016             Yamcs' CFDP packet link (10016)
``yamcs_cltu``            base + 5017             the CLTU input of Yamcs' frame link
``yamcs_tm_frames``       base + 5018             Yamcs' TM frame link (10018)
``yamcs_http``            base + 3090             Yamcs' web and API (8090)
========================  ======================  ===================================

The base is ``$OBSW_PORT_BASE`` if set (an operator's choice for this run), else the mission
file's ``"ports": {"base": N}``, else 5000. The same ``ports`` section may fix any named port
by itself (``"ports": {"base": 6000, "yamcs_http": 8080}``).

An APID becomes a port in one place, ``Ports.for_apid``: the port fixed by name for the
mission's ``pus`` or ``cfdp`` APID, else base + APID; ``Ports.routes`` is the table a frame
processor or gateway routes TC packets with (APID -> (host, port)).
"""

import os

from obsw_host.mission.errors import PortError

ENV = "OBSW_PORT_BASE"
DEFAULT_BASE = 5000

# offsets from the base of the ports that belong to no APID
OFFSETS = {
    "tm": -1,
    "playback": 0,
    "yamcs_pus": 5015,
    "yamcs_cfdp": 5016,
    "yamcs_cltu": 5017,
    "yamcs_tm_frames": 5018,
    "yamcs_http": 3090,
}
# ports of application processes, by the APID name they follow (offset after the APID)
BY_APID = {"pus": ("pus", 0), "cfdp": ("cfdp", 0), "cfdp_ground": ("cfdp", 1)}
NAMES = tuple(BY_APID) + tuple(OFFSETS)
YAMCS_LINKS = ("pus", "cfdp", "cltu", "tm_frames")  # Yamcs' link names, yamcs_<link> here


def _port(value, where):
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value < 65536:
        raise PortError("%s: expected a port number 0-65535, got %r" % (where, value))
    return value


def env_base(environ=None):
    """``$OBSW_PORT_BASE`` as an int, or None when it is not set."""
    text = (os.environ if environ is None else environ).get(ENV)
    if text is None or text == "":
        return None
    try:
        return _port(int(text, 0), ENV)
    except ValueError:
        raise PortError("%s: expected a port number, got %r" % (ENV, text)) from None


class Ports:
    """The ports of one system: ``base``, the mission's ``apids`` (name -> APID) and the ports
    ``fixed`` by name. ``where`` names the file in error messages."""

    def __init__(self, base=None, apids=None, fixed=None, where="ports"):
        self.where = where
        env = env_base()
        self.base = (
            env
            if env is not None
            else _port(DEFAULT_BASE if base is None else base, where + ": base")
        )
        self.apids = dict(apids or {})
        self.fixed = {}
        for name, port in (fixed or {}).items():
            if name not in NAMES:
                raise PortError(
                    "%s: %s: unknown port name (one of base, %s)" % (where, name, ", ".join(NAMES))
                )
            self.fixed[name] = _port(port, "%s: %s" % (where, name))

    @classmethod
    def from_section(cls, section, apids=None, where="ports"):
        """The ports of a mission file's ``ports`` section (a dict, or None: all defaults)."""
        section = dict(section or {})
        if not isinstance(section, dict):
            raise PortError('%s: expected an object such as {"base": 5000}' % where)
        base = section.pop("base", None)
        return cls(base, apids, section, where)

    def for_apid(self, apid):
        """The UDP port of the application process with APID ``apid``: the port the mission
        fixes by name for its ``pus`` or ``cfdp`` APID, else base + APID."""
        for name, (apid_name, offset) in BY_APID.items():
            if offset == 0 and self.apids.get(apid_name) == apid:
                return self.get(name)
        return self.base + apid

    def routes(self, host):
        """APID -> (``host``, port) for every APID of the mission (see ``for_apid``)."""
        return {apid: (host, self.for_apid(apid)) for apid in sorted(set(self.apids.values()))}

    def route(self, host):
        """A function APID -> (``host``, port) for any APID (``for_apid``)."""
        return lambda apid: (host, self.for_apid(apid))

    def get(self, name):
        """The port named ``name`` (one of ``NAMES``)."""
        if name in self.fixed:
            return self.fixed[name]
        if name in OFFSETS:
            return self.base + OFFSETS[name]
        if name in BY_APID:
            apid_name, offset = BY_APID[name]
            apid = self.apids.get(apid_name)
            if apid is None:
                raise PortError(
                    "%s: port %s needs APID %r, which the spacecraft database does not name"
                    % (self.where, name, apid_name)
                )
            return self.base + apid + offset
        raise PortError("%s: unknown port name %r" % (self.where, name))

    @property
    def pus(self):
        return self.get("pus")

    @property
    def cfdp(self):
        return self.get("cfdp")

    @property
    def cfdp_ground(self):
        return self.get("cfdp_ground")

    @property
    def tm(self):
        return self.get("tm")

    @property
    def playback(self):
        return self.get("playback")

    def yamcs(self):
        """Yamcs' link ports by link name (``pus``, ``cfdp``, ``cltu``, ``tm_frames``)."""
        return {link: self.get("yamcs_" + link) for link in YAMCS_LINKS}

    @property
    def yamcs_http(self):
        return self.get("yamcs_http")

    def table(self):
        """Every named port that can be computed, name -> port (for listings and docs)."""
        out = {}
        for name in NAMES:
            try:
                out[name] = self.get(name)
            except PortError:
                pass
        return out


def app_port(apid):
    """The UDP port of application process ``apid`` for the base of this run."""
    return Ports().for_apid(apid)


def default():
    """The ports of this run with no mission file (``$OBSW_PORT_BASE`` or 5000)."""
    return Ports()
