"""Which standard PUS message types the OBC serves, read from the service tables it registers.

A TC type is served when the provider the OBC registers for its service has a handler for the
subtype (``HANDLERS``); a TM type when that provider declares it among the reports it emits
(``REPORTS``; the core tests check that every TM a provider sends is declared). The OBC's
providers come from building its PUS application process from the mission configuration, as
``obsw obc serve`` does, without starting it: nothing here is a hand-kept list.
"""

import copy
import os
import shutil
import tempfile

from obsw.pus.sdb_services import FIRST_MISSION_TYPE

from obsw_host.mission import config as obc_config
from obsw_host.obc.topology import Topology
from obsw_host.obc.units import PusUnit
from obsw_host.pus.standard import MESSAGE_TYPES, SERVICE_NAMES


def obc_services(config_path=None):
    """{service type: provider} of the PUS process of the mission at ``config_path``
    (default: the one ``obsw_host.mission.locate`` finds), built in a throw-away state folder
    with no fixed port bound."""
    config = obc_config.load(config_path)
    config.doc = copy.deepcopy(config.doc)
    ports = config.doc.setdefault("ports", {})
    for name in ("pus", "cfdp", "cfdp_ground"):  # any free port: the mission's OBC may be up
        ports[name] = 0
    if "cfdp" in config.doc:
        config.doc["cfdp"].pop("port", None)
    topology = Topology(config)
    process = topology.process_of("pus")
    state = tempfile.mkdtemp(prefix="obsw-coverage-")
    config.state = state
    config.il_directory = os.path.join(state, "il")
    os.makedirs(config.il_directory)
    try:
        unit = PusUnit(topology, process, out=lambda *a: None)
        try:
            return dict(unit.app.services)
        finally:
            unit.transport.close()
            if unit.cfdp is not None:
                unit.cfdp.close()
    finally:
        shutil.rmtree(state, ignore_errors=True)


def serves(services, message_type):
    """True if ``services`` ({service: provider}) serve ``message_type`` (a MessageType)."""
    provider = services.get(message_type.service)
    if provider is None:
        return False
    if message_type.kind == "TC":
        return provider.handler(message_type.subtype) is not None
    return (message_type.service, message_type.subtype) in provider.REPORTS


def coverage(services):
    """The standard's table against ``services``: a JSON-able dict, by service, with totals."""
    out = []
    for service, name in SERVICE_NAMES.items():
        types = []
        for m in MESSAGE_TYPES:
            if m.service == service:
                types.append(
                    {
                        "type": "%s[%d,%d]" % (m.kind, m.service, m.subtype),
                        "subtype": m.subtype,
                        "kind": m.kind,
                        "name": m.name,
                        "title": m.title,
                        "served": serves(services, m),
                    }
                )
        provider = services.get(service)
        out.append(
            {
                "service": service,
                "name": name,
                "provider": type(provider).__name__ if provider is not None else None,
                "served": sum(1 for t in types if t["served"]),
                "total": len(types),
                "types": types,
            }
        )
    return {
        "served": sum(s["served"] for s in out),
        "total": sum(s["total"] for s in out),
        "services": out,
        "mission_services": mission_services(services),
    }


def mission_services(services):
    """The mission's own services (types 128..255) the OBC registers, apart from the
    standard's: each request (TC) and report (TM) its database declares, and whether the
    provider serves it."""
    out = []
    for number in sorted(n for n in services if n >= FIRST_MISSION_TYPE):
        provider = services[number]
        definition = getattr(provider, "definition", None)
        types = []
        for kind, table in (("TC", "requests"), ("TM", "reports")):
            for sub, m in sorted(getattr(definition, table, {}).items()):
                if kind == "TC":
                    served = provider.handler(sub) is not None
                else:
                    served = (number, sub) in provider.REPORTS
                types.append(
                    {
                        "type": "%s[%d,%d]" % (kind, number, sub),
                        "subtype": sub,
                        "kind": kind,
                        "name": m.name,
                        "served": served,
                    }
                )
        types.sort(key=lambda t: t["subtype"])
        out.append(
            {
                "service": number,
                "name": getattr(definition, "name", ""),
                "provider": type(provider).__name__,
                "served": sum(1 for t in types if t["served"]),
                "total": len(types),
                "types": types,
            }
        )
    return out


def markdown(report):
    """The coverage report as the Markdown page ``docs/pus-coverage.md``."""
    lines = [
        "# PUS-C coverage",
        "",
        "<!-- generated by `tools/pus_coverage_page.py` from `obsw pus coverage --json`;"
        " do not edit -->",
        "",
        "Every message type that ECSS-E-ST-70-41C defines for services 1 to 23, and whether the",
        "sample spacecraft's OBC serves it: a TC when the provider it registers for the service",
        "has a handler for the subtype, a TM when that provider emits it. The figures come from",
        "the service tables the OBC registers, not from a list kept by hand; run",
        "`obsw pus coverage` (or `obsw pus coverage --json`) to see them for your own mission.",
        "",
        "**%d of %d message types served.**" % (report["served"], report["total"]),
        "",
        "| service | name | served |",
        "|---|---|---|",
    ]
    for s in report["services"]:
        lines.append("| %d | %s | %d of %d |" % (s["service"], s["name"], s["served"], s["total"]))
    for s in report["services"]:
        lines += ["", "## ST[%02d] %s" % (s["service"], s["name"]), ""]
        lines += ["| type | standard name | constant | served |", "|---|---|---|---|"]
        for t in s["types"]:
            lines.append(
                "| %s | %s | `%s` | %s |"
                % (t["type"], t["title"], t["name"], "yes" if t["served"] else "**no**")
            )
    return "\n".join(lines) + "\n"
