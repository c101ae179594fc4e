"""``obsw mission upgrade``: a format-1 mission file converted to format 2.

Format 1 had no ``format`` key and a built-in ``solar_panel`` kind; format 2 says
``"format": 2`` and runs the solar panel as a mission component (a plug-in).
"""

from obsw_host.mission.defaults import FORMAT

RENAMED = {"solar_panel": ("SolarPanel", {"module": "obsw_host.solar_panel"})}


def upgrade(doc):
    """(format-2 document, list of changes in words) for mission document ``doc``."""
    if doc.get("format") == FORMAT:
        return doc, []
    changes = ["format: 2"]
    out = {"format": FORMAT}
    out.update(doc)
    procs = doc.get("processes")
    if isinstance(procs, dict):
        comps = dict(doc.get("components") or {})
        new_procs = {}
        for pname, kinds in procs.items():
            if not isinstance(kinds, list):
                new_procs[pname] = kinds
                continue
            row = []
            for k in kinds:
                if k in RENAMED:
                    name, spec = RENAMED[k]
                    comps.setdefault(name, dict(spec))
                    changes.append("processes.%s: kind %s is now component %s" % (pname, k, name))
                    k = name
                row.append(k)
            new_procs[pname] = row
        out["processes"] = new_procs
        if comps:
            out["components"] = comps
    return out, changes
