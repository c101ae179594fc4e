"""The operator's TM view and session log: what `obsw ground monitor` and `replay` print.

``Display(sdb)`` turns a TC or a decoded TM into one line: UTC time (the TM's on-board time),
APID, the message type and its name, then values by name with their units, events with their
severity, verification reports with the request they verify (named when this ground sent it)
and failure codes by name. ``SessionLog(path)`` appends every TC and TM, raw and decoded, as
one JSON object per line; ``replay(path, sdb)`` decodes such a log again, line by line.
"""

import json
import time

from obsw.pus.services.s01_verification import describe
from obsw.utc import format_utc

from obsw_host.pus import text
from obsw_host.pus.display import tm_seconds
from obsw_host.pus.tai import TAI_MINUS_UNIX

_COLOURS = {"TC": "36", "fail": "31", "high": "31", "medium": "33", "low": "33", "ok": "32"}


def utc_now():
    return format_utc(time.time() + TAI_MINUS_UNIX)


class Display:
    """One line per packet for an operator (see the module text)."""

    def __init__(self, sdb=None, colour=False, raw=False, config=None):
        self.sdb = sdb
        self.colour = colour
        self.raw = raw  # raw parameter values instead of engineering ones
        self.config = config  # the mission's PusConfig: its TM time code (default: PUS-C's)
        self.sent = {}  # (apid, seq) -> TC this ground sent, to name verification reports

    def _paint(self, line, kind):
        code = _COLOURS.get(kind)
        return "\x1b[%sm%s\x1b[0m" % (code, line) if self.colour and code else line

    def tc(self, tc, when=None):
        self.sent[(tc.apid, tc.seq_count)] = tc
        line = "%s  TC apid %4d seq %5d  TC[%d,%d] %s" % (
            when or utc_now(),
            tc.apid,
            tc.seq_count,
            tc.service,
            tc.subtype,
            text.name(tc.service, tc.subtype),
        )
        return self._paint(line, "TC")

    def tm(self, tm, decoded, when=None, config=None):
        """One line for a TM: its on-board time in UTC, else ``when`` (a logged time), else
        now."""
        tai = tm_seconds(tm, config or self.config)
        when = format_utc(tai) if tai else (when or utc_now())
        head = "%s  TM apid %4d seq %5d  TM[%d,%d] " % (
            when,
            tm.apid,
            tm.seq_count,
            tm.service,
            tm.subtype,
        )
        kind = None
        if decoded is None:
            body = "%s (not decoded: %s)" % (text.name(tm.service, tm.subtype), tm.data.hex())
        elif tm.service == 1:
            body, kind = self._verification(decoded)
        elif tm.service == 5 and "severity" in decoded:
            body, kind = self._event(decoded)
        elif tm.service == 9 and isinstance(decoded.get("time"), (int, float)):
            body = "%s: %s UTC, rate 2**%s s, status %s" % (
                text.name(tm.service, tm.subtype) or "time report",
                format_utc(decoded["time"]),
                decoded.get("exponent", "?"),
                decoded.get("status", "?"),
            )
        else:
            body = text.name(tm.service, tm.subtype)
            summary = self.values(decoded)
            if summary:
                body += ": " + summary
        return self._paint(head + body, kind)

    def _verification(self, report):
        rid = report["request_id"]
        tc = self.sent.get((rid.apid, rid.seq_count))
        what = "TC apid %d seq %d" % (rid.apid, rid.seq_count)
        if tc is not None:
            what += " TC[%d,%d] %s" % (tc.service, tc.subtype, text.name(tc.service, tc.subtype))
        return "%s: %s" % (what, describe(report)), ("ok" if report["success"] else "fail")

    def _event(self, ev):
        name = ev.get("event", "event %d" % ev["id"])
        data = ev.get("labelled", ev.get("data"))
        body = "event %s (%s)" % (name, ev["severity"])
        if isinstance(data, dict) and data:
            body += ": " + ", ".join("%s=%s" % (k, _num(v)) for k, v in data.items())
        elif data:
            body += ": data " + bytes(data).hex()
        return body, ev["severity"]

    def values(self, decoded):
        """``name=value unit, ..`` for reports of parameter values, else the text summary."""
        if isinstance(decoded, dict) and isinstance(decoded.get("values"), dict):
            parts = [
                "%s=%s" % (k, text.value_text(self.sdb, k, v, self.raw))
                for k, v in decoded["values"].items()
            ]
            if "sid" in decoded:
                parts.insert(0, "structure %s" % decoded["sid"])
            return ", ".join(parts)
        if isinstance(decoded, dict):
            return text.pairs(text.plain(decoded))
        return str(text.plain(decoded))


def _num(v):
    return "%.6g" % v if isinstance(v, float) else text.plain(v)


class SessionLog:
    """Every TC and TM of a session, appended to ``path`` as JSON lines."""

    def __init__(self, path):
        self.file = open(path, "a", encoding="utf-8")

    def write(self, direction, raw, decoded=None, line=""):
        record = {"utc": utc_now(), "dir": direction, "raw": bytes(raw).hex(), "text": line}
        if decoded is not None:
            record["decoded"] = text.plain(decoded)
        self.file.write(json.dumps(record) + "\n")
        self.file.flush()

    def close(self):
        self.file.close()


class ReplayError(ValueError):
    """A session log line that is not a record this log writes."""


def replay(path, sdb=None, colour=False):
    """Yield one display line per record of the session log at ``path``, decoded again."""
    from obsw.pus.tc import PusTc

    from obsw_host.pus.ground import Ground

    with Ground(sdb, target=("127.0.0.1", 9)) as g:  # its service users decode; nothing is sent
        display = Display(sdb, colour)
        with open(path, encoding="utf-8") as f:
            for n, line in enumerate(f, 1):
                if not line.strip():
                    continue
                try:
                    record = json.loads(line)
                    raw = bytes.fromhex(record["raw"])
                    direction = record["dir"]
                except (ValueError, KeyError, TypeError) as e:
                    raise ReplayError(
                        "%s:%d: expected a session log record (JSON with dir, raw), got %r: %s"
                        % (path, n, line.strip()[:60], e)
                    ) from None
                if direction == "TC":
                    yield display.tc(PusTc.unpack(raw), record.get("utc"))
                    continue
                result = g.proc.receive(raw)
                if result is None:
                    yield "%s  TM (malformed, %d bytes) %s" % (
                        record.get("utc"),
                        len(raw),
                        raw.hex(),
                    )
                else:
                    yield display.tm(result[0], result[1], record.get("utc"), g.proc.config)
