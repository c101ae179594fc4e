"""What an operator sees of the spacecraft's state: current values with units and limit state,
the latest events, and the commands sent with their verification stages.

``limit_state(parameter, value)`` compares a value with the database's ``limits``
(``{"warning": [low, high], "critical": [low, high]}``) and ``range``: ``"ok"``, ``"warning"``,
``"critical"``, ``"out of range"``, or ``""`` when the database gives no limits (or the value
is not a number). ``Picture`` takes every decoded TM a ground receives (``feed``) and keeps
the state that `obsw ground watch` shows; ``snapshot()`` is its JSON-able form.
"""

import collections

from obsw.pus.config import DEFAULT
from obsw.pus.services.s05_events import SEVERITY_NAMES
from obsw.utc import format_utc

from obsw_host.pus import text

LIMIT_STATES = ("ok", "warning", "critical", "out of range")
STAGES = {1: "accepted", 3: "started", 5: "progress", 7: "completed"}
FAILED_STAGES = {2: "acceptance", 4: "start", 6: "progress", 8: "completion", 10: "routing"}


def _outside(bounds, value):
    if not isinstance(bounds, (list, tuple)) or len(bounds) != 2:
        return False
    low, high = bounds
    return (low is not None and value < low) or (high is not None and value > high)


def limit_state(parameter, value):
    """The limit state of ``value`` of ``parameter`` (an sdb Parameter; see the module text)."""
    if parameter is None or isinstance(value, bool) or not isinstance(value, (int, float)):
        return ""
    limits = getattr(parameter, "limits", None) or {}
    valid = getattr(parameter, "range", None)
    if valid and _outside(valid, value):
        return "out of range"
    if _outside(limits.get("critical"), value):
        return "critical"
    if _outside(limits.get("warning"), value):
        return "warning"
    return "ok" if (limits or valid) else ""


def parameter_of(sdb, key):
    """The database's parameter of ``key`` (name or id), or None."""
    if sdb is None:
        return None
    try:
        return sdb.parameter(key)
    except (KeyError, ValueError, TypeError, AttributeError):
        return None


def number(value):
    return "%.6g" % value if isinstance(value, float) else str(text.plain(value))


def tm_seconds(tm, config=None):
    """A TM's on-board time as TAI seconds since 1958 (the time code's fields turned into
    seconds by ``config.time``, the default PUS layout's CUC when not given), or None."""
    t = getattr(tm, "time", None)
    if isinstance(t, (int, float)):
        return t or None
    code = getattr(config or DEFAULT, "time", None)
    if not isinstance(t, (list, tuple)) or code is None or not any(t):
        return None
    try:
        return code.to_seconds(*t)
    except (TypeError, ValueError):
        return None


def utc(tai):
    """On-board TAI seconds as UTC ISO text, or '' when there is no time."""
    return format_utc(tai) if isinstance(tai, (int, float)) and tai else ""


class Picture:
    """The state an operator watches, built from the TM a ground receives."""

    def __init__(self, sdb=None, events=10, commands=10, config=None):
        self.sdb = sdb
        self.config = config  # the PusConfig the TM was decoded with (its time code)
        self.values = collections.OrderedDict()  # name -> {value, unit, limit, time}
        self.events = collections.deque((), events)
        self.commands = collections.OrderedDict()  # (apid, seq) -> row
        self.keep_commands = commands
        self.received = 0

    def sent(self, tc, when=""):
        """Record a TC this ground sent, so its verification reports are shown by name."""
        row = self._command(tc.apid, tc.seq_count)
        row["request"] = "TC[%d,%d] %s" % (
            tc.service,
            tc.subtype,
            text.name(tc.service, tc.subtype),
        )
        row["sent"] = when

    def _command(self, apid, seq):
        key = (apid, seq)
        row = self.commands.pop(key, None) or {
            "apid": apid,
            "seq_count": seq,
            "request": "TC apid %d seq %d" % (apid, seq),
            "stages": [],
            "sent": "",
        }
        self.commands[key] = row
        while len(self.commands) > self.keep_commands:
            self.commands.popitem(last=False)
        return row

    def feed(self, tm, decoded):
        """Take one received TM (and its decoded form, or None)."""
        self.received += 1
        if not isinstance(decoded, dict):
            return
        when = utc(tm_seconds(tm, self.config))
        if tm.service == 1 and "request_id" in decoded:
            rid = decoded["request_id"]
            row = self._command(rid.apid, rid.seq_count)
            if decoded.get("success"):
                row["stages"].append(STAGES.get(tm.subtype, "report %d" % tm.subtype))
            else:
                stage = FAILED_STAGES.get(tm.subtype, "stage %d" % tm.subtype)
                row["stages"].append("%s failed (%s)" % (stage, text.summary(tm, decoded)))
        elif tm.service == 5 and "severity" in decoded:
            self.events.appendleft(self._event(decoded, when))
        elif isinstance(decoded.get("values"), dict):
            for name, value in decoded["values"].items():
                self.update(name, value, when)

    def update(self, name, value, when=""):
        p = parameter_of(self.sdb, name)
        self.values[str(name)] = {
            "value": text.plain(value),
            "unit": (p.unit or "") if p is not None else "",
            "limit": limit_state(p, value),
            "time": when,
        }

    def _event(self, ev, when):
        data = ev.get("data")
        if isinstance(data, dict):
            data = ", ".join("%s=%s" % (k, number(v)) for k, v in data.items())
        elif data:
            data = bytes(data).hex()
        severity = ev.get("severity")
        return {
            "time": when,
            "event": ev.get("event", "event %s" % ev.get("id")),
            "severity": SEVERITY_NAMES.get(severity, severity),
            "data": data or "",
        }

    def snapshot(self):
        """The picture as JSON-able data."""
        return {
            "values": [dict(name=k, **v) for k, v in self.values.items()],
            "events": list(self.events),
            "commands": [dict(r) for r in reversed(self.commands.values())],
            "received": self.received,
        }
