"""Every default of a mission, in one place: what the OBC uses and what the schemas say.

``SECTIONS`` maps a mission file's section to its defaults; a mission file's section overrides
them key by key (``section(config, "pus")``); nothing else in the OBC writes a default of its
own. The shipped JSON Schemas carry the same values as ``default`` annotations, as an editor
shows them (``schema_section("platform")`` is ``{"heartbeat": 0.5, ...}``); a test keeps the
two equal.
"""

import json
import os

from obsw.reconfig import recovery as _recovery

SCHEMA_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "schema")
MISSION_SCHEMA = os.path.join(SCHEMA_DIR, "mission.schema.json")
SDB_SCHEMA = os.path.join(SCHEMA_DIR, "sdb.schema.json")
MISSION_FILE = "mission.json"  # the mission file's name in a mission folder
FORMAT = 2  # the mission file format this version writes and reads

_cache = {}


def schema(path):
    """The JSON Schema at ``path`` (parsed once per process)."""
    s = _cache.get(path)
    if s is None:
        with open(path, encoding="utf-8") as f:
            s = _cache[path] = json.load(f)
    return s


def _resolve(root, node):
    while "$ref" in node:
        node = root["$defs"][node["$ref"].rsplit("/", 1)[1]]
    return node


def schema_section(name, path=MISSION_SCHEMA):
    """Defaults of the keys of top-level object ``name`` (a fresh dict)."""
    root = schema(path)
    props = _resolve(root, root["properties"][name]).get("properties", {})
    out = {}
    for key, node in props.items():
        node = _resolve(root, node) if "default" not in node else node
        if "default" in node:
            out[key] = json.loads(json.dumps(node["default"]))  # a copy callers may change
    return out


def top(key, path=MISSION_SCHEMA):
    """The default of top-level key ``key`` (None: no default)."""
    return schema(path)["properties"][key].get("default")


# the OBC's defaults, section by section
PUS = {
    "period": 0.1,  # seconds per activity cycle
    "playback_rate": 64,  # packets per second service 15 plays back
    "device_timeout": 5.0,  # seconds service 2 waits for a device
    "service_timeout": 5.0,  # seconds a mission service (128..255) waits for its component
    "follow_period": 0.25,  # seconds between looks for components that (re)appeared
    "time_code": "cuc",  # ST[09] time reports: "cuc" (TM[9,2]) or "cds" (TM[9,3])
    "monitoring": [],  # ST[12] limit checks installed at the first start (obc.monitoring)
}
CFDP = {
    "peers": {},
    "poll": 0.005,  # seconds between the CFDP entity's steps
}  # ports and ids: obsw_host.mission.ports and obsw_host.mission.ids (the mission's)
OBCP = {"timeout": 2.0, "activity_timeout": 30.0, "level": 2, "step_period": 0.01}
SPACECAN = {
    "interface": "virtual",
    "channels": ["can0", "can1"],
    "heartbeat_period": 0.5,
    "timeout": 0.5,
    "retries": 2,
    "simulate": False,
}
FRAMES = {
    "uart_a": "pty",
    "uart_b": "pty",
    "tm_frame_length": 256,
    "clcw_period": 0.5,
    "uart_queue": 64,  # frames waiting for a UART; beyond, the oldest is dropped (counted)
    "tc_security": "sdls",  # TC frames authenticated; "none" only when the mission says so
    # the space link (obsw_host.frames.coding): CCSDS 131.0-B TM coding at both ends
    "tm_coding": {
        "scheme": "none",  # none | rs | conv | concatenated
        "rs_e": 16,  # (255,223); 8: (255,239)
        "interleave": 1,  # 1, 2, 3, 4, 5 or 8
        "randomize": True,
        "sync": {"search_errors": 3, "lock_errors": 6, "verify": 2, "flywheel": 3, "slip": 2},
    },
    "downlink_bps": None,  # the radio's rate: frames paced to it; None: the UART's speed
    "uplink_bps": None,
    "tm_spill": 262144,  # octets of TM packets kept while their VC is full
    # the simulation's radio model (obsw_sim.radio)
    "radio": {
        "ber": 0.0,
        "ebn0_db": None,  # AWGN on soft symbols instead of ber
        "burst_rate": 0.0,
        "burst_length": 8,
        "slip_rate": 0.0,
        "seed": 1,
    },
}
PLATFORM = {
    "heartbeat": 0.5,  # seconds between heartbeats
    "deadline": 3.0,  # a process silent this long is hung: killed and restarted
    "start_timeout": 20.0,  # a process's first heartbeat may take this long
    "max_failures": 3,  # this many deaths or hangs of processes that ran healthy ...
    "window": 60.0,  # ... within this many seconds: power-cycle the OBC
    "power_cycle": {"component": "CpduN", "line": 0, "off_ms": 500},
    "crash_loop": 3,  # this many deaths in a row before a first heartbeat: stop the process
    # supervision (obsw_host.obc.supervision): the hardware watchdog and health telemetry
    "watchdog": None,  # watchdog device (e.g. "/dev/watchdog"); None: no hardware watchdog
    "watchdog_timeout": 15,  # seconds without a kick before the board resets (Pi: at most 15)
    "critical": None,  # processes the watchdog waits for; None: every process
    "health_period": 1.0,  # seconds between samples of the OBC's health telemetry
    "health_root": "/",  # where /proc and /sys are (a simulated tree in tests)
    "disk": None,  # the file system whose use is reported; None: the state folder's
    "thermal_zone": "thermal_zone0",  # /sys/class/thermal/<zone>/temp: the SoC's sensor
    # the UART link to the reconfiguration module (obsw_host.obc.module_link): heartbeats,
    # the OBC's context in its safeguard memory and the DS3231's time at start
    "module_uarts": None,  # the serial devices to its two controllers; None: no link
    "context_period": 1.0,  # seconds between context saves
    # seconds to wait for the module's time and context at start (a save's answer: half of it)
    "module_timeout": 1.0,
}
# in-flight software updates (obsw_host.update): signed packages, two slots, a trial and rollback
UPDATE = {
    "public_key": None,  # the ground's Ed25519 public key file (hex); None: updates refused
    "deadline": 60.0,  # seconds a version on trial has to report healthy, else rolled back
    "healthy_after": 3.0,  # seconds every process must answer heartbeats before the self-test
    "max_starts": 3,  # starts of a version on trial (power cycles) before the boot falls back
    "self_test": None,  # the mission's own test of a new version: "module:function"
}
# the reconfiguration module's autonomous recovery of the OBC (delivered to the boards in their
# mission.json, obsw.reconfig.mission); the module's own fallback is the same table, in the core
CONTACT = {
    "stores": [],  # service 15 stores dumped at AOS, by priority; none: TM in real time
    "hold": 10.0,  # seconds in contact after the last TC heard (outside the pass table)
    "downlink_bps": None,  # the dump's rate; None: the frames section's, else 9600
    "share": 0.8,  # the share of the downlink the dump may take
}
RECOVERY = dict(_recovery.DEFAULTS, lines=list(_recovery.DEFAULTS["lines"]))
SECTIONS = {
    "pus": PUS,
    "cfdp": CFDP,
    "obcp": OBCP,
    "spacecan": SPACECAN,
    "frames": FRAMES,
    "platform": PLATFORM,
    "recovery": RECOVERY,
    "contact": CONTACT,
    "update": UPDATE,
}


def section(config, name):
    """Section ``name`` of ``config`` over its defaults (a new dict)."""
    out = dict(SECTIONS.get(name, {}))
    out.update(config.section(name))
    return out
