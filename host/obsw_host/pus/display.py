"""What an operator sees of the spacecraft's state: current values with units and limit state,
the latest events, and the commands sent with their verification stages.

``limit_state(parameter, value)`` compares a value with the database's ``limits``
(``{"warning": [low, high], "critical": [low, high]}``) and ``range``: ``"ok"``, ``"warning"``,
``"critical"``, ``"out of range"``, or ``""`` when the database gives no limits (or the value
is not a number). ``Picture`` takes every decoded TM a ground receives (``feed``) and keeps
the state that `obsw ground watch` shows; ``snapshot()`` is its JSON-able form.
"""

import collections
import json
import time

from obsw import cbor
from obsw.pus.config import DEFAULT
from obsw.pus.services.s05_events import SEVERITY_NAMES
from obsw.pus.services.s08_functions import functions
from obsw.pus.services.s12_layouts import CHECK_NAMES, STATUS_NAMES
from obsw.pus.services.s20_parameters import values_layout
from obsw.pus.tc import PusTc
from obsw.utc import format_utc

from obsw_host.pus import text
from obsw_host.pus.catalog import table

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

    def __init__(self, sdb=None, events=10, commands=10, config=None, clock=time.monotonic):
        self.sdb = sdb
        self.clock = clock
        self.last_tm = None  # the clock's time of the last TM received (None: none yet)
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
        self.last_tm = self.clock()
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
        """The value of parameter ``name`` as reported (raw); kept in engineering units, the
        limit state from the engineering value (the database's limits are in them)."""
        p = parameter_of(self.sdb, name)
        eng = value
        if p is not None:
            try:
                eng = text.engineering(self.sdb, name, value)
            except (ValueError, TypeError):
                eng = value
        row = {
            "value": text.plain(eng),
            "unit": (p.unit or "") if p is not None else "",
            "limit": limit_state(p, eng),
            "time": when,
        }
        if eng != value:
            row["raw"] = text.plain(value)
        self.values[str(name)] = row

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

    def signal(self, los_after):
        """(text, lost): how long ago the last TM came; lost (loss of signal) when none came
        for ``los_after`` seconds, or none yet."""
        if self.last_tm is None:
            return "no TM received", True
        age = self.clock() - self.last_tm
        if age >= los_after:
            return "LOSS OF SIGNAL: no TM for %.0f s (values as last received)" % age, True
        return "last TM %.1f s ago" % age, False

    def snapshot(self, los_after=None):
        """The picture as JSON-able data (with the signal when ``los_after`` is given)."""
        out = {
            "values": [dict(name=k, **v) for k, v in self.values.items()],
            "events": list(self.events),
            "commands": [dict(r) for r in reversed(self.commands.values())],
            "received": self.received,
        }
        if los_after is not None:
            text_, lost = self.signal(los_after)
            out["signal"] = {"text": text_, "lost": lost}
        return out


# ------------------------------------------------------------------------------ replies by name


def parameter_name(sdb, pid):
    p = parameter_of(sdb, pid)
    return p.qualified if p is not None else str(pid)


def event_name(sdb, eid):
    if not eid:
        return "-"
    try:
        return sdb.event(eid).qualified
    except (KeyError, ValueError, TypeError, AttributeError):
        return str(eid)


def request_text(raw, sdb=None):
    """A TC (bytes or hex) as an operator reads it: its type, name and decoded arguments."""
    try:
        tc = PusTc.unpack(bytes.fromhex(raw) if isinstance(raw, str) else bytes(raw))
    except ValueError:
        return "(undecodable TC %s)" % (raw if isinstance(raw, str) else bytes(raw).hex())
    head = "TC[%d,%d] %s" % (tc.service, tc.subtype, text.name(tc.service, tc.subtype))
    try:
        detail = _request_detail(tc, sdb)
    except (ValueError, KeyError, TypeError, IndexError):
        detail = tc.data.hex()
    return head + (": " + detail if detail else "")


def _request_detail(tc, sdb):
    if sdb is None:
        return tc.data.hex()
    if (tc.service, tc.subtype) == (8, 1):
        fid = int.from_bytes(bytes(tc.data[:2]), "big")
        fn = functions(sdb).get(fid)
        if fn is None:
            return "function %d" % fid
        names = {a[0]: a[1] for a in fn.arguments}
        given = fn.layout.unpack(tc.data)["args"]
        args = ", ".join(
            "%s=%s" % (names.get(a["id"], a["id"]), number(a["value"])) for a in given
        )
        return "%s(%s)" % (fn.name, args)
    if (tc.service, tc.subtype) == (20, 3):
        layout = values_layout(lambda pid: sdb.parameter(pid).type)
        items = layout.unpack(tc.data)["items"]
        return ", ".join(
            "%s=%s" % (parameter_name(sdb, i["id"]), number(i["value"])) for i in items
        )
    return tc.data.hex()


def _limit_text(sdb, pid, value, raw=False):
    """A raw value of parameter ``pid`` in engineering units (``raw``: as it is), with its
    unit."""
    return text.value_text(sdb, pid, value, raw).split(" (raw")[0]


def named_row(row, sdb=None, raw=False):
    """One row of a report (monitoring definitions, out-of-limits, event-actions, ..) with its
    ids, codes and times by name: parameters, events, check types and states, UTC times,
    decoded TCs, values with units."""
    out = collections.OrderedDict()
    pid = row.get("parameter")
    for key, value in row.items():
        if key in ("parameter", "validity") and isinstance(value, int):
            if key == "validity" and not value:
                continue
            value = parameter_name(sdb, value)
        elif key in ("validity_mask", "validity_value") and not row.get("validity"):
            continue
        elif key == "check" and isinstance(value, int):
            value = CHECK_NAMES.get(value, value)
        elif key in ("previous", "current", "checking", "status") and isinstance(value, int):
            value = STATUS_NAMES.get(value, value)
        elif (key == "event" or key.endswith("_event")) and isinstance(value, int):
            value = event_name(sdb, value)
        elif key == "time" and isinstance(value, (int, float)):
            key, value = "time (UTC)", utc(value)
        elif key == "request":
            value = request_text(value, sdb)
        elif key in ("address", "start_address") and isinstance(value, int):
            value = "0x%08X" % value
        elif key == "checksum" and isinstance(value, int):
            value = "0x%04X" % value
        elif key in ("value", "limit", "low", "high", "expected") and isinstance(
            value, (int, float)
        ):
            value = _limit_text(sdb, pid, value, raw)
        elif key == "type" and isinstance(value, list) and len(value) == 2:
            continue  # the type of the embedded request: its text says it
        elif isinstance(value, bool):
            value = "yes" if value else "no"
        elif isinstance(value, (dict, list)):
            value = json.dumps(text.plain(value))
        out[key] = value
    return out


def _files(v):
    rows = [{"name": n, "type": "directory"} for n in v.get("directories", [])]
    rows += [{"name": n, "type": "file"} for n in v.get("files", [])]
    if not rows:
        rows = [{"name": o.get("name"), "type": o.get("type")} for o in v.get("objects", [])]
    listing = table(rows) if rows else "(empty)"
    return "%s\n%s" % (v.get("repository", ""), listing)


TIME_KEYS = ("time", "start", "end", "oldest", "newest", "open_start")


def _is_time(key):
    return key in TIME_KEYS or key.endswith("_time")


def _rows(items):
    return isinstance(items, list) and items and all(isinstance(x, dict) for x in items)


def readable(value, sdb=None, raw=False):
    """A reply as an operator reads it: lists of items as tables of rows by name (see
    ``named_row``), statistics per parameter, a directory listing as a table, found paths one a
    line, times in UTC (``raw``: raw values, not engineering); else ``text.readable``."""
    v = text.plain(value)
    if not isinstance(v, dict):
        return text.readable(value, sdb, raw)
    if "repository" in v and ("files" in v or "objects" in v):
        return _files(v)
    special = _structure(v, sdb) or _reporting(v) or _forwarded(v) or _registers(v)
    if special:
        return special
    if set(v) in ({"functional"}, {"definitions"}):  # service 12's own tables (text)
        return text.readable(value, sdb, raw)
    if isinstance(v.get("paths"), list):
        return "\n".join(v["paths"]) or "(nothing found)"
    if isinstance(v.get("statistics"), dict):
        rows = []
        for name, st in v["statistics"].items():
            row = collections.OrderedDict(parameter=name)
            for k, x in st.items():
                if _is_time(k):
                    row[k + " (UTC)"] = utc(x) or "-"
                else:
                    row[k] = number(x) if k == "samples" else _limit_text(sdb, name, x, raw)
            rows.append(row)
        head = "from %s to %s" % (utc(v.get("start")) or "-", utc(v.get("end")) or "-")
        return head + "\n" + (table(rows) if rows else "(no statistics)")
    lists = [k for k, x in v.items() if _rows(x)]
    if lists:
        parts = []
        for k, x in v.items():
            if k not in lists and not isinstance(x, (list, dict)):
                parts.append("%s: %s" % (k, utc(x) if _is_time(k) else x))
        for k in lists:
            parts.append(table([_timed(named_row(x, sdb, raw)) for x in v[k]]))
        return "\n".join(parts)
    if isinstance(v.get("obcps"), list):
        return "(no OBCPs)"
    if all(not isinstance(x, (list, dict)) for x in v.values()) and len(v) > 1:
        return "\n".join(
            "%s: %s" % (k, (utc(x) or "-") if _is_time(k) else _cell(x)) for k, x in v.items()
        )
    return text.readable(value, sdb, raw)


def _structure(v, sdb):
    """TM[3,10]/[3,12]: a report structure's definition, its parameters by name."""
    if not {"sid", "enabled", "interval", "parameters"} <= set(v):
        return ""
    head = "structure %s: %s, collection interval %s" % (
        v["sid"],
        "enabled" if v["enabled"] else "disabled",
        v["interval"],
    )
    rows = [{"parameter": parameter_name(sdb, p), "group": "-"} for p in v["parameters"]]
    for n, g in enumerate(v.get("groups") or (), 1):
        for p in g.get("parameters", ()):
            group = "%d (x%s)" % (n, g.get("repetitions"))
            rows.append({"parameter": parameter_name(sdb, p), "group": group})
    return head + "\n" + (table(rows) if rows else "(no parameters)")


def _reporting(v):
    """TM[3,40]: functional reporting definitions, a row per report definition."""
    defs = v.get("definitions") if set(v) == {"definitions"} else None
    if not isinstance(defs, dict) or not all(isinstance(d, dict) for d in defs.values()):
        return ""
    rows = []
    for fid, kinds in defs.items():
        for kind, sids in kinds.items():
            for sid, (enabled, interval) in sids.items():
                on = "yes" if enabled else "no"
                row = {"definition": fid, "kind": kind, "structure": sid, "enabled": on}
                row["interval"] = interval
                rows.append(row)
    return table(rows) if rows else "(no functional reporting definitions)"


def _forwarded(v):
    """TM[14,4/8/12]: the structures forwarded in real time, by APID."""
    if len(v) != 1 or next(iter(v)) not in ("hk", "diag"):
        return ""
    kind, by_apid = next(iter(v.items()))
    if not isinstance(by_apid, dict):
        return ""
    rows = [{"apid": a, kind: ", ".join(map(str, ids)) or "all"} for a, ids in by_apid.items()]
    return table(rows) if rows else "no %s structure forwarded" % kind


def _registers(v):
    """TM[2,6]: register dump, addresses in hex (node << 16 | parameter id on SpaceCAN)."""
    regs = v.get("registers") if set(v) == {"registers"} else None
    if not isinstance(regs, list):
        return ""
    rows = [{"address": "0x%08X" % a, "value": number(x)} for a, x in regs]
    return table(rows) if rows else "(no registers)"


def _timed(row):
    """Times of a row (TAI seconds) in UTC; 0 as '-'."""
    for k in list(row):
        if _is_time(k) and isinstance(row[k], (int, float)):
            row[k] = utc(row[k]) or "-"
    return row


def _cell(x):
    return ("yes" if x else "no") if isinstance(x, bool) else number(x)


def component_said(data):
    """``CODE: message (name=value, ..)`` from a component error record (CBOR), or ''."""
    try:
        code, message, detail = cbor.loads(bytes(data))
    except (ValueError, TypeError):
        return ""
    out = "%s" % code
    if message and message != code:
        out += ": %s" % message
    if isinstance(detail, dict) and detail:
        out += " (%s)" % ", ".join("%s=%s" % (k, number(v)) for k, v in detail.items())
    elif detail is not None:
        out += " (%s)" % number(detail)
    return out


def failure_detail(tx, sdb=None):
    """What a failure report's data means for the TC it verifies: for a function, its name and
    what the component said; else ``text.failure_detail``."""
    failure = getattr(tx, "failure", None)
    data = failure.get("data") if isinstance(failure, dict) else None
    if sdb is None or not data or tx.tc.service != 8 or len(data) < 2:
        return text.failure_detail(tx, sdb)
    fid = int.from_bytes(bytes(data[:2]), "big")
    fn = functions(sdb).get(fid)
    out = "function %s" % (fn.name if fn else fid)
    said = component_said(data[2:]) if len(data) > 2 else ""
    return out + (": " + said if said else "")
