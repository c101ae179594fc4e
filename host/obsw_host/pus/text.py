"""One readable line per PUS packet, and JSON-able forms of decoded values."""

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
    (17, 1): "are-you-alive",
    (17, 2): "are-you-alive report",
    (17, 3): "on-board connection test",
    (17, 4): "connection test report",
    (20, 1): "report parameter values",
    (20, 2): "parameter value report",
    (20, 3): "set parameter values",
}


def name(service, subtype):
    return NAMES.get((service, subtype), "")


def plain(value):
    """``value`` with RequestIds, bytes and tuples turned into JSON-able forms."""
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


def _values(decoded):
    parts = []
    for k, v in decoded.items():
        if isinstance(v, float):
            v = "%.6g" % v
        elif isinstance(v, dict):
            v = "{%s}" % _values(v)
        elif isinstance(v, list):
            v = "[%s]" % ", ".join(
                ("{%s}" % _values(x)) if isinstance(x, dict) else str(plain(x)) for x in v
            )
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
    return _values(decoded)


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
