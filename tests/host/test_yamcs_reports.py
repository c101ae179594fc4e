"""Every report the OBC's services send has a whole XTCE container (Yamcs decodes them all in
``test_yamcs_e2e.py::test_every_report_is_decoded``).

The report types come from the service tables (each provider's ``REPORTS``), not from a
list kept by hand: a service that starts sending a new report fails here until the report has
its layout in ``obsw_host.yamcs.report_layouts`` or a hand-written container.
"""

import importlib
import os
import pkgutil
import sys
import xml.etree.ElementTree as ET

import obsw.pus.services as services_package
import pytest
from obsw.pus.config import from_sdb
from obsw.pus.fields import field
from obsw.pus.sdb import load as load_sdb
from obsw.pus.services.base import Service
from obsw_host.sample import SDB_PATH
from obsw_host.yamcs import database, xtce
from obsw_host.yamcs.report_layouts import HAND_WRITTEN, report_layouts
from obsw_host.yamcs.xtce_reports import PID

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from report_samples import Sampler  # noqa: E402

NS = {"x": "http://www.omg.org/spec/XTCE/20180204"}
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def service_reports():
    """{(service, subtype): provider class} of every provider in obsw.pus.services."""
    found = {}
    for info in pkgutil.iter_modules(services_package.__path__):
        module = importlib.import_module("obsw.pus.services." + info.name)
        for obj in vars(module).values():
            if isinstance(obj, type) and issubclass(obj, Service):
                for msg_type in obj.REPORTS:
                    found[tuple(msg_type)] = obj
    return found


def conditions(root):
    """The (service, subtype) pairs the containers match (subtype None: any)."""
    out = set()
    for c in root.iter("{%s}SequenceContainer" % NS["x"]):
        cond = {}
        for cmp in c.findall("x:BaseContainer/x:RestrictionCriteria//x:Comparison", NS):
            cond[cmp.get("parameterRef").rsplit("/", 1)[-1]] = cmp.get("value")
        if "service" in cond:
            sub = cond.get("subtype")
            out.add((int(cond["service"]), None if sub is None else int(sub)))
    return out


def generated(mission):
    sc = database.load(os.path.join(ROOT, "examples", mission, "sdb.json"))
    return sc, ET.fromstring(xtce.generate(sc))


def test_the_service_tables_send_many_report_types():
    assert len(service_reports()) >= 70


@pytest.mark.parametrize("mission", ["sample", "aurora"])
def test_every_report_type_has_a_whole_container(mission):
    sc, root = generated(mission)
    matched = conditions(root)
    layouts = report_layouts(lambda pid: field(*sc.params[pid].pair))
    missing = []
    for msg_type, provider in sorted(service_reports().items()):
        if msg_type[0] >= 128:
            continue  # a mission service's reports, from its own definition
        if msg_type not in layouts and msg_type not in HAND_WRITTEN:
            missing.append((msg_type, provider.__name__, "no layout"))
        elif msg_type not in matched and (msg_type[0], None) not in matched:
            missing.append((msg_type, provider.__name__, "no container"))
    assert not missing


def test_layouts_pack_and_unpack_their_samples():
    sc = database.load(SDB_PATH)
    layouts = report_layouts(lambda pid: field(*sc.params[pid].pair))
    sampler = Sampler(1, from_sdb(load_sdb(SDB_PATH)), 10)
    for _, (name, layout) in sorted(layouts.items()):
        values = sampler.layout(layout)
        assert layout.unpack(layout.pack(values)) is not None, name


def test_value_reports_find_database_parameters_by_alias():
    sc, root = generated("sample")
    aliases = {}
    for p in root.iter("{%s}Parameter" % NS["x"]):
        for a in p.iter("{%s}Alias" % NS["x"]):
            aliases.setdefault(a.get("nameSpace"), {})[a.get("alias")] = p.get("name")
    assert aliases[PID]["1"] == "angle"  # SolarPanel.angle
    assert set(aliases[PID]) >= {str(pid) for pid, p in sc.params.items() if p.pair[0] != 7}
    report = next(
        c
        for c in root.iter("{%s}SequenceContainer" % NS["x"])
        if c.get("name") == "parameter_values_items_item"
    )
    entry = report.find(".//x:IndirectParameterRefEntry", NS)
    assert entry.get("aliasNameSpace") == PID
    # a check transition fills the monitored parameter's own check state, each transition
    states = aliases["pus-check-state"]
    assert states["2"] == "speed_check_state"
