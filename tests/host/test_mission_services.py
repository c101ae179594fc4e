"""Mission services (types 128..255) on the host: the mission check, the service table, the
catalog, coverage, XTCE, PLUTO's signatures, and Aurora-1's service 140 end to end through
`obsw obc serve examples/aurora` and `obsw ground service`."""

import copy
import json
import os
import shutil

from obsw.pus import sdb as sdb_module
from obsw.pus.services.mission import MissionService
from obsw_host.mission.check import check
from obsw_host.mission.ids import MissionIds
from obsw_host.pus.catalog import catalog
from obsw_host.pus.onboard import SERVICES, service_table
from obsw_host.yamcs import database
from obsw_host.yamcs.xtce import generate
from test_mission_examples import AURORA, ENV, Obc, free_base, obsw, wait_for_ping

AURORA_SDB = os.path.join(AURORA, "sdb.json")


def aurora_copy(tmp_path, edit):
    """examples/aurora copied to ``tmp_path`` with ``edit(services)`` applied to its sdb."""
    folder = tmp_path / "aurora"
    shutil.copytree(AURORA, folder)
    path = folder / "sdb.json"
    doc = json.loads(path.read_text())
    edit(doc["services"])
    path.write_text(json.dumps(doc))
    return str(folder)


def problems(folder):
    _, found = check(os.path.join(str(folder), "mission.json"))
    return [str(p) for p in found]


def test_aurora_declares_service_140_and_passes_the_check():
    db = sdb_module.load(AURORA_SDB)
    mtq = db.service("mtq")
    assert mtq.type == 140 and mtq.component == "Magnetorquer"
    assert [r.name for r in mtq.requests.values()] == ["dipole", "degauss"]
    assert problems(AURORA) == []


def test_the_check_names_each_mistake_where_it_is(tmp_path):
    def edit(services):
        svc = services[0]
        svc["requests"][0]["operation"] = "set_dipol"
        svc["requests"][1]["subtype"] = 2  # the report's
        svc["reports"][1]["event"] = "saturation"
        services.append(copy.deepcopy(svc))  # type and name twice

    found = problems(aurora_copy(tmp_path, edit))
    text = "\n".join(found)
    assert "$.services[0].requests[0].operation: Magnetorquer has no operation set_dipol" in text
    assert "did you mean 'set_dipole'" in text
    assert "$.services[0].reports[0].subtype: subtype 2 is also degauss's" in text
    assert "$.services[0].reports[1].event: Magnetorquer has no event saturation" in text
    assert "$.services[1].type: service type 140 is also mtq's" in text
    assert '$.services[1].name: service "mtq" declared twice' in text


def test_the_check_refuses_standard_types_and_arguments_out_of_order(tmp_path):
    def edit(services):
        services[0]["type"] = 20
        args = services[0]["requests"][0]["arguments"]
        args[0], args[1] = args[1], args[0]

    text = "\n".join(problems(aurora_copy(tmp_path, edit)))
    assert "$.services[0].type" in text and "128" in text
    assert "Magnetorquer.set_dipole takes (x, y, z)" in text and "got (y, x, z)" in text


def test_one_row_of_the_service_table_per_declared_service():
    db = sdb_module.load(AURORA_SDB)
    table = service_table(db)
    assert table[: len(SERVICES)] == SERVICES
    (number, needs, build), *rest = table[len(SERVICES) :]
    assert (number, needs, rest) == (140, (), [])


def test_the_catalog_lists_requests_and_reports():
    rows = catalog(sdb_module.load(AURORA_SDB), "services")
    assert [r["type"] for r in rows] == ["TC[140,1]", "TM[140,2]", "TC[140,3]", "TM[140,4]"]
    assert rows[0]["does"] == "Magnetorquer.set_dipole -> dipole_report"
    assert "x: float32 A.m^2 [-0.2, 0.2]" in rows[0]["fields"]
    assert rows[3]["does"] == "on Magnetorquer.saturated"


def test_pluto_checks_a_procedure_against_the_requests_signature():
    db = sdb_module.load(AURORA_SDB)
    op = db.operations["Magnetorquer.set_dipole"]
    assert op.signature == [("x", "float32", "A.m^2"), ("y", "float32", "A.m^2"),
                            ("z", "float32", "A.m^2")]  # fmt: skip


def test_aurora_service_140_end_to_end(tmp_path):
    base = free_base(42)
    env = dict(ENV, OBSW_PORT_BASE=str(base))
    ground = ["ground", "--sdb", AURORA_SDB, "--apid", 42, "--port", base + 42]
    obc = Obc(AURORA, tmp_path / "state", env)
    try:
        wait_for_ping(ground, obc)
        # checked on the ground: nothing is sent
        r = obsw(*ground, "service", "mtq", "dipole", "x=0.5", "y=0", "z=0")
        assert r.returncode == 2 and "x = 0.5 outside [-0.2, 0.2] A.m^2" in r.stderr, r.stderr
        r = obsw(*ground, "service", "mtq", "dipole", "x=0.1", "y=0")
        assert r.returncode == 2 and "needs argument z" in r.stderr, r.stderr
        r = obsw(*ground, "service", "mtq", "dipol")
        assert r.returncode == 2 and "no request or report 'dipol'" in r.stderr, r.stderr
        # the component refuses while disabled: the completion fails with its reason
        r = obsw(*ground, "service", "mtq", "dipole", "x=0.1", "y=0", "z=0")
        assert r.returncode == 1 and "completion failure: component error" in r.stdout, r.stdout
        assert "(request mtq.dipole)" in r.stdout, r.stdout
        assert obsw(*ground, "function", "Magnetorquer.enable").returncode == 0
        r = obsw(*ground, "service", "mtq", "dipole", "x=0.1", "y=0", "z=0")
        assert r.returncode == 0, r.stdout + r.stderr
        assert "mtq.dipole_report" in r.stdout and "magnitude = 0.1" in r.stdout, r.stdout
        assert "A.m^2" in r.stdout
        r = obsw(*ground, "--json", "service", "140", "1", "x=0", "y=0.05", "z=0")
        reply = json.loads(r.stdout)
        assert reply["ok"] and reply["replies"][0]["fields"]["magnitude"] > 0.049, reply
        r = obsw(*ground, "service", "mtq", "degauss")
        assert r.returncode == 0 and "progress success step 1" in r.stdout, r.stdout
        # the component's saturated event as TM[140,4], seen by a monitoring ground
        r = obsw(*ground, "params", "set", "Magnetorquer.max_dipole=0.05")
        assert r.returncode == 0, r.stdout + r.stderr
        r = obsw(*ground, "-v", "service", "mtq", "dipole", "x=0.1", "y=0", "z=0")
        assert r.returncode == 1 and "component error" in r.stdout, r.stdout
        assert "TM[140,4]" in r.stderr and "saturation_report" in r.stderr, r.stderr
        r = obsw(*ground, "list", "services")
        assert "TC[140,1]" in r.stdout and "mtq.saturation_report" in r.stdout
    finally:
        out = obc.stop()
    assert "Traceback" not in out


def test_coverage_lists_mission_services_apart():
    env = dict(ENV)
    r = obsw("pus", "coverage", AURORA, "--json", env=env)
    assert r.returncode == 0, r.stderr
    report = json.loads(r.stdout)
    assert report["total"] == 318  # the standard's, unchanged
    (mission,) = report["mission_services"]
    assert mission["service"] == 140 and mission["name"] == "mtq"
    assert mission["provider"] == MissionService.__name__
    assert mission["served"] == mission["total"] == 4
    r = obsw("pus", "coverage", AURORA, env=env)
    assert "mission services" in r.stdout and "140" in r.stdout


def test_xtce_has_the_mission_service_commands_and_reports():
    # on the sample's database: Aurora-1's has an octet-string parameter XTCE export lacks
    doc = json.loads(open(os.path.join(AURORA, "..", "sample", "sdb.json")).read())
    doc["services"] = json.loads(open(AURORA_SDB).read())["services"]
    doc["services"][0]["component"] = "SolarPanel"
    db = sdb_module.Sdb(doc)
    text = generate(database.from_sdb(db, MissionIds(db, None)))
    root = "/" + db.mission
    assert '<SpaceSystem name="mtq">' in text and '<MetaCommand name="dipole"' in text
    assert 'SequenceContainer name="mtq_dipole_report"' in text
    assert 'SequenceContainer name="mtq_saturation_report"' in text
    assert '<Comparison parameterRef="%s/service" value="140"' % root in text
    assert 'name="dipole_report_magnitude"' in text
