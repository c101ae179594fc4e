"""One readable line per PUS packet, and JSON-able forms of decoded values.

Parameter values travel raw (the database's ``type``); what operators read is the engineering
value in its ``unit`` (calibrated, or the enumeration's label), with the raw value beside it
when the two differ: ``Coil.temp = 20 degC (raw 1400)``. ``raw=True`` shows raw values only.
"""

from obsw.pus.calibration import CalibrationError
from obsw.pus.packets import RequestId
from obsw.pus.services.s01_verification import describe

NAMES = {
    (1, 1): "acceptance success",
    (1, 2): "acceptance failure",
    (1, 3): "start success",
    (1, 4): "start failure",
    (1, 5): "progress success",
    (1, 6): "progress failure",
    (1, 7): "completion success",
    (1, 8): "completion failure",
    (1, 10): "routing failure",
    (3, 1): "create HK structure",
    (3, 3): "delete HK structures",
    (3, 5): "enable periodic HK",
    (3, 6): "disable periodic HK",
    (3, 9): "report HK structures",
    (3, 10): "HK structure report",
    (3, 25): "HK parameter report",
    (3, 27): "one-shot HK",
    (3, 31): "modify collection interval",
    (5, 1): "event (info)",
    (5, 2): "event (low)",
    (5, 3): "event (medium)",
    (5, 4): "event (high)",
    (5, 5): "enable events",
    (5, 6): "disable events",
    (5, 7): "report disabled events",
    (5, 8): "disabled events report",
    (9, 1): "set time report rate",
    (9, 2): "CUC time report",
    (18, 1): "load OBCP",
    (18, 2): "unload OBCP",
    (18, 3): "activate OBCP",
    (18, 4): "stop OBCP",
    (18, 5): "suspend OBCP",
    (18, 6): "resume OBCP",
    (18, 7): "communicate parameters to OBCP",
    (18, 8): "report OBCP status",
    (18, 9): "OBCP status report",
    (18, 12): "abort OBCP",
    (18, 13): "load OBCP by reference",
    (18, 16): "set OBCP observability",
    (18, 17): "abort all OBCPs",
    (18, 18): "aborted OBCPs report",
    (18, 19): "load by reference and activate OBCP",
    (18, 20): "stop and unload OBCP",
    (18, 21): "start OBCP engine",
    (18, 22): "stop OBCP engine",
    (17, 1): "are-you-alive",
    (17, 2): "are-you-alive report",
    (17, 3): "on-board connection test",
    (17, 4): "connection test report",
    (20, 1): "report parameter values",
    (20, 2): "parameter value report",
    (20, 3): "set parameter values",
    (20, 4): "change raw memory parameter definitions",
    (20, 5): "change object memory parameter definitions",
    (20, 6): "report parameter definitions",
    (20, 7): "parameter definition report",
    (8, 1): "perform function",
    (11, 1): "enable time-based schedule",
    (11, 2): "disable time-based schedule",
    (11, 3): "reset time-based schedule",
    (11, 4): "insert activities",
    (11, 5): "delete activities",
    (11, 6): "delete activities by filter",
    (11, 7): "time-shift activities",
    (11, 8): "time-shift activities by filter",
    (11, 9): "detail-report activities",
    (11, 10): "time-based schedule detail report",
    (11, 11): "detail-report activities by filter",
    (11, 12): "summary-report activities",
    (11, 13): "time-based schedule summary report",
    (11, 14): "summary-report activities by filter",
    (11, 15): "time-shift all activities",
    (11, 16): "detail-report all activities",
    (11, 17): "summary-report all activities",
    (11, 18): "report sub-schedule status",
    (11, 19): "sub-schedule status report",
    (11, 20): "enable sub-schedules",
    (11, 21): "disable sub-schedules",
    (11, 22): "create scheduling groups",
    (11, 23): "delete scheduling groups",
    (11, 24): "enable scheduling groups",
    (11, 25): "disable scheduling groups",
    (11, 26): "report group status",
    (11, 27): "group status report",
    (12, 1): "enable parameter monitoring",
    (12, 2): "disable parameter monitoring",
    (12, 3): "change transition reporting delay",
    (12, 4): "delete all parameter monitoring",
    (12, 5): "add parameter monitoring",
    (12, 6): "delete parameter monitoring",
    (12, 7): "modify parameter monitoring",
    (12, 8): "report parameter monitoring",
    (12, 9): "parameter monitoring report",
    (12, 10): "report out-of-limits",
    (12, 11): "out-of-limits report",
    (12, 12): "check transition report",
    (12, 13): "report monitoring status",
    (12, 14): "monitoring status report",
    (12, 15): "enable parameter monitoring function",
    (12, 16): "disable parameter monitoring function",
    (12, 17): "enable functional monitoring function",
    (12, 18): "disable functional monitoring function",
    (12, 19): "enable functional monitoring",
    (12, 20): "disable functional monitoring",
    (12, 21): "protect functional monitoring",
    (12, 22): "unprotect functional monitoring",
    (12, 23): "add functional monitoring",
    (12, 24): "delete functional monitoring",
    (12, 25): "report functional monitoring",
    (12, 26): "functional monitoring report",
    (12, 27): "report functional monitoring status",
    (12, 28): "functional monitoring status report",
    (19, 1): "add event-actions",
    (19, 2): "delete event-actions",
    (19, 3): "delete all event-actions",
    (19, 4): "enable event-actions",
    (19, 5): "disable event-actions",
    (19, 6): "report event-action status",
    (19, 7): "event-action status report",
    (19, 8): "enable event-action function",
    (19, 9): "disable event-action function",
    (19, 10): "report event-actions",
    (19, 11): "event-action definitions report",
    (21, 1): "load request sequence",
    (21, 3): "unload request sequence",
    (21, 4): "activate request sequence",
    (21, 5): "abort request sequence",
    (21, 6): "report sequence status",
    (21, 7): "sequence status report",
    (21, 9): "checksum request sequence",
    (21, 10): "sequence checksum report",
    (21, 11): "report sequence content",
    (21, 12): "sequence content report",
    (21, 13): "abort all sequences",
    (21, 14): "aborted sequences report",
    (22, 4): "insert position-tagged activities",
    (22, 10): "position-based schedule detail report",
    (22, 13): "position-based schedule summary report",
    (22, 16): "detail-report all position-tagged activities",
}

for (_s, _t), _n in list(NAMES.items()):  # service 22 mirrors service 11
    if _s == 11:
        NAMES.setdefault(
            (22, _t), _n.replace("time-based", "position-based").replace("time-", "position-")
        )


def name(service, subtype):
    return NAMES.get((service, subtype), "")


_UNSAFE = set(range(0x20)) | set(range(0x7F, 0xA0)) | {0x200E, 0x200F, 0x2028, 0x2029}
_UNSAFE |= set(range(0x202A, 0x202F)) | set(range(0x2066, 0x206A))  # bidirectional overrides


def escape(s):
    """A string that came from the spacecraft, safe to print on one line: control characters
    (terminal escape sequences, carriage returns, new lines) and bidirectional overrides as
    ``\\xNN`` / ``\\uNNNN``, so no TM can move the cursor, recolour or fake a line."""
    if not any(ord(c) in _UNSAFE or c == "\\" for c in s):
        return s
    out = []
    for c in s:
        o = ord(c)
        if c == "\\":
            out.append("\\\\")
        elif o in _UNSAFE:
            out.append("\\x%02x" % o if o < 0x100 else "\\u%04x" % o)
        else:
            out.append(c)
    return "".join(out)


def plain(value):
    """``value`` with RequestIds, bytes and tuples turned into JSON-able forms; strings with
    their control characters escaped (``escape``)."""
    if isinstance(value, str):
        return escape(value)
    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if isinstance(value, (bytes, bytearray)):
        return bytes(value).hex()
    if isinstance(value, RequestId):
        return {"apid": value.apid, "seq_count": value.seq_count}
    if isinstance(value, float):
        return round(value, 6)
    return value


def pairs(decoded):
    """``name=value, ...`` of a decoded dict (nested dicts in braces, lists in brackets)."""
    parts = []
    for k, v in decoded.items():
        if isinstance(v, float):
            v = "%.6g" % v
        elif isinstance(v, dict):
            v = "{%s}" % pairs(v)
        elif isinstance(v, list):
            v = "[%s]" % ", ".join(
                ("{%s}" % pairs(x)) if isinstance(x, dict) else str(plain(x)) for x in v
            )
        else:
            v = plain(v)
        parts.append("%s=%s" % (k, v))
    return ", ".join(parts)


def summary(tm, decoded):
    """What a decoded TM says, in a few words."""
    if decoded is None:
        return "(not decoded, %d bytes)" % len(tm.data)
    if tm.service == 1:
        rid = decoded["request_id"]
        return "%s for TC seq %d" % (describe(decoded), rid.seq_count)
    if (tm.service, tm.subtype) == (9, 2):
        from obsw.utc import format_utc

        return "%s UTC, rate 2**%d s, status %d" % (
            format_utc(decoded["time"]),
            decoded["exponent"],
            decoded["status"],
        )
    return pairs(decoded)


def tc_line(tc, note=""):
    return "TC -> apid %4d seq %5d  TC[%d,%d] %s%s" % (
        tc.apid,
        tc.seq_count,
        tc.service,
        tc.subtype,
        name(tc.service, tc.subtype),
        ("  " + note) if note else "",
    )


def tm_line(tm, decoded):
    label = name(tm.service, tm.subtype)
    text = summary(tm, decoded)
    if tm.service == 1:
        return "TM <- apid %4d seq %5d  TM[%d,%d] %s" % (
            tm.apid,
            tm.seq_count,
            tm.service,
            tm.subtype,
            text,
        )
    return "TM <- apid %4d seq %5d  TM[%d,%d] %s%s" % (
        tm.apid,
        tm.seq_count,
        tm.service,
        tm.subtype,
        label,
        (": " + text) if text else "",
    )


def transaction(tx):
    """A finished (or timed-out) transaction as a JSON-able dict."""
    return {
        "request": "TC[%d,%d]" % (tx.tc.service, tx.tc.subtype),
        "apid": tx.tc.apid,
        "seq_count": tx.tc.seq_count,
        "ok": tx.ok,
        "done": tx.done,
        "verification": tx.verification(),
        "replies": plain(tx.replies),
        "failure": plain(tx.failure) if tx.failure else None,
    }


# ------------------------------------------------------------------------------ for operators


def _utc(tai):
    from obsw.utc import format_utc

    return format_utc(tai)


def _request_text(raw):
    from obsw.pus.tc import PusTc

    try:
        tc = PusTc.unpack(bytes.fromhex(raw) if isinstance(raw, str) else bytes(raw))
    except ValueError:
        return "(undecodable TC)"
    return "TC[%d,%d] %s" % (tc.service, tc.subtype, name(tc.service, tc.subtype))


def _activity(a):
    row = {}
    if "time" in a:
        row["release (UTC)"] = _utc(a["time"])
    if "position" in a:
        row["position"] = a["position"]
    row["id"] = "%s:%s:%s" % (a.get("source", 0), a.get("apid", 0), a.get("seq_count", 0))
    if "request" in a:
        row["request"] = _request_text(a["request"])
    for k in ("subschedule", "group"):
        if k in a:
            row[k] = a[k]
    return row


def _event_name(sdb, eid):
    try:
        return sdb.event(eid).qualified
    except (KeyError, ValueError, AttributeError):
        return str(eid)


def _number(x):
    return "%.6g" % x if isinstance(x, float) else str(plain(x))


def _parameter(sdb, key):
    if sdb is None:
        return None
    try:
        return sdb.parameter(key)
    except (KeyError, ValueError):
        return None


def mission_report(v, sdb=None):
    """A report of a mission service: its name, then each field with its unit."""
    units = {}
    try:
        report = sdb.service(v["service"]).message(v["report"])
        units = {f.name: f.unit for f in report.fields}
    except (AttributeError, KeyError):
        pass  # no database, or another one: the names alone
    lines = ["%s.%s" % (v["service"], v["report"])]
    for k, x in v["fields"].items():
        unit = units.get(k)
        lines.append("%s = %s%s" % (k, _number(x), " " + unit if unit else ""))
    return "\n".join(lines)


def value_text(sdb, key, raw_value, raw=False):
    """A parameter's value as an operator reads it: engineering value and unit, the raw value
    in parentheses when it differs (``raw``: the raw value and its raw unit only)."""
    p = _parameter(sdb, key)
    if p is None:
        return _number(raw_value)
    if raw:
        return _number(raw_value) + (" " + p.raw_unit if p.raw_unit else "")
    try:
        eng = p.engineering(raw_value)
    except (CalibrationError, TypeError):
        return "%s (raw, outside the calibration)" % _number(raw_value)
    unit = p.unit if p.unit and not isinstance(eng, str) else ""
    text = _number(eng) + (" " + unit if unit else "")
    if eng != raw_value or isinstance(eng, str):
        text += " (raw %s)" % _number(raw_value)
    return text


def engineering(sdb, key, raw_value):
    """The engineering value of ``raw_value`` of parameter ``key`` (raw if it has none)."""
    p = _parameter(sdb, key)
    if p is None:
        return raw_value
    try:
        return p.engineering(raw_value)
    except (CalibrationError, TypeError):
        return raw_value


_LIMIT_KEYS = ("low", "high", "value", "limit")


_EVENT_KEYS = ("event", "low_event", "high_event")
_PARAMETER_KEYS = ("parameter", "validity")


def _engineering_row(row, sdb, raw):
    """A service 12 row as operators read it: event and parameter names instead of IDs, a
    limit check's limits and values in engineering units (``raw``: left as they are)."""
    if raw or sdb is None:
        return row
    out = dict(row)
    if row.get("check") == 1 and "parameter" in row:
        for k in _LIMIT_KEYS:
            x = out.get(k)
            if isinstance(x, (int, float)) and not isinstance(x, bool):
                out[k] = value_text(sdb, row["parameter"], x).split(" (raw")[0]
    for k in _EVENT_KEYS:
        if out.get(k):
            out[k] = _event_name(sdb, out[k])
    for k in _PARAMETER_KEYS:
        if k == "validity" and not row.get("validity_mask"):
            continue
        p = _parameter(sdb, out.get(k)) if isinstance(out.get(k), int) else None
        if p is not None:
            out[k] = p.qualified
    return out


def readable(value, sdb=None, raw=False):
    """A reply as an operator reads it: names, engineering values with units (``raw``: raw
    values), UTC times, tables for lists."""
    from obsw_host.pus.catalog import table

    v = plain(value)
    if not isinstance(v, dict):
        return str(v)
    if v == {"alive": True}:
        return "alive"
    if set(v) == {"service", "report", "fields"} and isinstance(v["fields"], dict):
        return mission_report(v, sdb)
    if isinstance(v.get("values"), dict):
        lines = ["structure %s" % v["sid"]] if "sid" in v else []
        for k, x in v["values"].items():
            lines.append("%s = %s" % (k, value_text(sdb, k, x, raw)))
        return "\n".join(lines)
    for key in ("functional", "definitions"):
        if set(v) == {key} and isinstance(v[key], list):
            rows = [_engineering_row(r, sdb, raw) for r in v[key]]
            return table([{k: _cell(x) for k, x in r.items()} for r in rows])
    if isinstance(v.get("activities"), list):
        return table([_activity(a) for a in v["activities"]])
    if set(v) == {"ids"} and isinstance(v["ids"], list):
        return "disabled events: " + (", ".join(_event_name(sdb, i) for i in v["ids"]) or "none")
    if set(v) <= {"items", "delay"} and isinstance(v.get("items"), list):
        rows = [x if isinstance(x, dict) else {"item": x} for x in v["items"]]
        rows = [_engineering_row(r, sdb, raw) for r in rows]
        return table([{k: _cell(x) for k, x in r.items()} for r in rows])
    return json_text(v)


def _cell(x):
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, (dict, list)):
        return json_text(x)
    return x


def json_text(v):
    import json

    return json.dumps(v)


def failure_detail(tx, sdb=None):
    """What a failure report's data means for the TC it verifies, or ''."""
    failure = getattr(tx, "failure", None)
    if not failure or sdb is None:
        return ""
    data = failure.get("data") if isinstance(failure, dict) else None
    if tx.tc.service == 8 and data and len(data) == 2:
        fid = int.from_bytes(bytes(data), "big")
        from obsw.pus.services.s08_functions import functions

        fn = functions(sdb).get(fid)
        return "function %s" % (fn.name if fn else fid)
    if tx.tc.service == 20 and data and len(data) >= 2:  # the ID, then why as text
        pid = int.from_bytes(bytes(data[:2]), "big")
        p = _parameter(sdb, pid)
        why = bytes(data[2:]).decode("utf-8", "replace")
        return "parameter %s%s" % (p.qualified if p is not None else pid, why and ": " + why)
    if tx.tc.service in sdb.services and data and len(data) == 1:
        return _mission_failure(sdb.services[tx.tc.service], tx.tc.subtype, failure, data[0])
    return ""


def _mission_failure(service, subtype, failure, index):
    """A mission service's failure data: the argument out of range (acceptance, its index),
    else the request's subtype."""
    request = service.requests.get(subtype)
    if request is None:
        return ""
    if failure.get("stage") == 1 and index < len(request.fields):
        f = request.fields[index]
        return "argument %s of %s, range %s" % (f.name, request.qualified, list(f.range or ()))
    return "request %s" % request.qualified
