"""What a spacecraft database offers an operator, as rows for tables or JSON.

``catalog(sdb, kind)`` lists ``parameters``, ``functions``, ``events`` or ``hk`` (housekeeping
structures); ``table(rows)`` lays rows out as aligned text columns.
"""

from obsw.pus.services.s05_events import SEVERITY_NAMES
from obsw.pus.services.s08_functions import functions

KINDS = ("parameters", "functions", "events", "hk")


def _type(spec):
    """A type's name: the database's spelling, or a field type's name."""
    if isinstance(spec, str):
        return spec
    return getattr(spec, "name", None) or str(spec)


def parameters(sdb):
    out = []
    for pid in sorted(sdb.parameters):
        p = sdb.parameters[pid]
        out.append(
            {
                "id": pid,
                "name": p.qualified,
                "type": _type(p.type_spec),
                "unit": p.unit or "",
                "writable": "yes" if p.writable else "no",
                "range": _bounds(p.values.range if p.values else None),
                "values": _conversion(p.values),
            }
        )
    return out


def _bounds(pair):
    if pair is None:
        return ""
    return "[%s, %s]" % tuple("" if x is None else x for x in pair)


def _conversion(values):
    """How raw values become engineering ones: calibrated, labels, or nothing."""
    if values is None:
        return ""
    if values.labels:
        return ", ".join("%d=%s" % kv for kv in sorted(values.labels.items()))
    cal = values.calibration
    if cal is None:
        return ""
    return "polynomial" if hasattr(cal, "coefficients") else "point pairs"


def function_rows(sdb):
    out = []
    for fid, f in sorted(functions(sdb).items()):
        text = ", ".join("%s: %s" % (a[1], _type(a[2])) for a in f.arguments)
        out.append({"id": fid, "name": f.name, "arguments": text})
    return out


def events(sdb):
    out = []
    for eid in sorted(sdb.events):
        e = sdb.events[eid]
        data = ", ".join("%s: %s" % (name, _type(t)) for name, t in e.fields)
        out.append(
            {
                "id": eid,
                "name": e.qualified,
                "severity": SEVERITY_NAMES.get(e.severity, e.severity),
                "data": data,
            }
        )
    return out


def _name(sdb, key):
    try:
        return sdb.parameter(key).qualified
    except (KeyError, ValueError):
        return str(key)


def housekeeping(sdb):
    out = []
    for s in sdb.housekeeping:
        out.append(
            {
                "sid": s.get("sid"),
                "interval": s.get("interval", ""),
                "enabled": "yes" if s.get("enabled") else "no",
                "parameters": ", ".join(_name(sdb, p) for p in s.get("parameters", ())),
            }
        )
    return out


def catalog(sdb, kind):
    """Rows (dicts) of ``kind``, one of KINDS."""
    return {"parameters": parameters, "functions": function_rows, "events": events}.get(
        kind, housekeeping
    )(sdb)


def table(rows, columns=None):
    """``rows`` (dicts) as text: a header line, then one aligned line per row."""
    if not rows:
        return "(none)"
    columns = columns or list(rows[0])
    cells = [[str(c) for c in columns]] + [[str(r.get(c, "")) for c in columns] for r in rows]
    widths = [max(len(line[i]) for line in cells) for i in range(len(columns))]
    return "\n".join(
        "  ".join(v.ljust(w) for v, w in zip(line, widths)).rstrip() for line in cells
    )
