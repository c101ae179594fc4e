"""`obsw mission check` and `obsw obc serve` agree on every mistake of a corpus: the realistic
mistakes already refused (``test_mission_check.MISTAKES``, made in the sample) and those that
used to pass the check and misbehave in flight (``IN_FLIGHT`` below, made in examples/aurora:
a team's own plug-in, calibrated parameters, monitoring). For each, the check refuses in lines
naming the file, the JSON path and what was expected, and serve refuses with the same lines,
before any process starts. For each of ``IN_FLIGHT``, the OBC's own code, given the mistake
without the check, fails or degrades (the witness): the check refuses what flight would."""

import json
import os
import shutil
import subprocess

import pytest
from obsw.il.clock import SimClock
from obsw.pus.app import ApplicationProcess
from obsw.pus.parameters import ParameterPool
from obsw.pus.sdb import load as load_sdb
from obsw.pus.services.s03_housekeeping import Housekeeping
from obsw.pus.services.s12_monitoring import OnBoardMonitoring
from obsw_host import sample
from obsw_host.mission.check import check
from obsw_host.mission.config import ConfigError, MissionConfig
from obsw_host.obc import monitoring
from obsw_host.obc.plugins import components
from obsw_host.obc.topology import Topology
from test_mission_check import BOUND, ENV, MISTAKES, OBSW, attribute, component, mission, sdb

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
AURORA = os.path.join(ROOT, "examples", "aurora")


def _monitor(**changes):
    return mission(lambda d: d["pus"]["monitoring"][0].update(changes))


def _add_monitor(entry):
    return mission(lambda d: d["pus"]["monitoring"].append(entry))


def _attr(comp, name, **changes):
    return sdb(lambda d: attribute(d, comp, name).update(changes))


def _big_structure(d):
    d["parameters"] += [{"name": "cam.frame_a", "id": 2000, "type": [7, 40000]},
                        {"name": "cam.frame_b", "id": 2001, "type": [7, 40000]}]  # fmt: skip
    d["housekeeping"].append({"sid": 30, "parameters": ["cam.frame_a", "cam.frame_b"]})


def _no_power_cycle(folder):
    path = os.path.join(folder, "nodes", "cpdu.json")
    with open(path) as f:
        doc = json.load(f)
    doc["functions"] = [f for f in doc["functions"] if f.get("function_name") != "power_cycle"]
    with open(path, "w") as f:
        json.dump(doc, f)


def _extra(comp, key, entry):
    return sdb(lambda d: component(d, comp)[key].append(entry))


# ------------------------------------------------------------------------ witnesses: flight


def _mission(folder):
    with open(os.path.join(folder, "mission.json")) as f:
        return MissionConfig(json.load(f), os.path.join(folder, "mission.json"))


def build_components(folder):
    """What a process does first: build each component with the mission's options."""
    for c in components(_mission(folder)).values():
        c.build()


def install_monitoring(folder):
    """What the PUS process does at its first start: install pus.monitoring."""
    db = load_sdb(os.path.join(folder, "sdb.json"))
    app = ApplicationProcess(42, lambda raw: None, SimClock(0.0))
    app.register(OnBoardMonitoring(ParameterPool(db), db.events))
    monitoring.install(app, db, _mission(folder).doc["pus"]["monitoring"])
    pmon = app.services[12].pmons[len(app.services[12].pmons)]
    for key in ("low", "high"):  # the definition is reported (TM[12,9]) with its raw limits
        db.parameter(pmon.d["parameter"]).type.pack(pmon.d[key])


def report_structures(folder):
    """What service 3 does: a one-shot report of every initial structure."""
    db = load_sdb(os.path.join(folder, "sdb.json"))
    sent = []
    app = ApplicationProcess(42, sent.append, SimClock(0.0))
    pool = ParameterPool(db)
    for p in db.parameters.values():  # fixed-size octet strings hold values of their size
        if p.type.ptc == 7 and p.type.bits:
            pool.values[p.id] = bytes(p.type.bits // 8)
    hk = Housekeeping(pool, db.housekeeping)
    app.register(hk)
    for s in db.housekeeping:
        if hk.generate(s["sid"]) is None:
            raise ValueError("structure %d: no report (%s)" % (s["sid"], app.counters))


def read_attributes(folder):
    """What a read of each database attribute does: the component's value at its extreme,
    packed in the database's type (a parameter report)."""
    from obsw_host.mission.crosscheck import _INT

    topology = Topology(_mission(folder))
    db = load_sdb(os.path.join(folder, "sdb.json"))
    served = {i.name: i for i in topology.interfaces()}
    for p in db.parameters.values():
        itf = served.get(p.component)
        if itf is None:
            continue
        m = itf.members.get(p.name)
        if m is None or m.member != 1:
            raise KeyError("%s has no attribute %s" % (p.component, p.name))
        if m.writable is False and p.writable:
            raise PermissionError("%s is read-only" % p.qualified)
        extreme = {"f64": 1e300, "str": "MTQ-A", "bool": True}.get(m.type)
        if m.type in _INT:
            extreme = _INT[m.type][1]
        if extreme is not None:
            p.type.pack(extreme)


def read_events(folder):
    topology = Topology(_mission(folder))
    db = load_sdb(os.path.join(folder, "sdb.json"))
    db.check_interfaces(topology.interfaces())


def read_defaults(folder):
    """What the pool gives for a parameter no component has published yet."""
    db = load_sdb(os.path.join(folder, "sdb.json"))
    pool = ParameterPool(db)
    for p in db.parameters.values():
        p.type.check(pool.get(p.id))


def power_cycle_operation(folder):
    topology = Topology(_mission(folder))
    pc = _mission(folder).doc["platform"]["power_cycle"]
    itf = [i for i in topology.equipment_interfaces() if i.name == pc["component"]][0]
    if "power_cycle" not in itf.members:
        raise AttributeError("%s has no power_cycle" % itf.name)


# (name, spoil, file, JSON path of the line, text, witness: the OBC's code that fails)
IN_FLIGHT = [
    ("misspelt component option", mission(lambda d: d["components"]["Magnetorquer"]["options"]
     .update(max_dipol=0.1)), "mission.json", "$.components.Magnetorquer.options.max_dipol",
     "did you mean 'max_dipole'?", build_components),
    ("option the class lacks", mission(lambda d: d["components"]["Magnetorquer"]["options"]
     .update(coils=3)), "mission.json", "$.components.Magnetorquer.options.coils",
     "takes no option \"coils\"", build_components),
    ("monitoring names an unknown event", _monitor(high_event="monitoring.coil_hott"),
     "mission.json", "$.pus.monitoring[0].high_event", "did you mean 'monitoring.coil_hot'?",
     install_monitoring),
    ("monitoring names an unknown parameter", _monitor(parameter="Magnetorquer.coil_tmp"),
     "mission.json", "$.pus.monitoring[0].parameter", "did you mean 'Magnetorquer.coil_temp'?",
     install_monitoring),
    ("monitoring limit beyond the calibration", _monitor(low=-400), "mission.json",
     "$.pus.monitoring[0]", "-400 outside the calibration's points", install_monitoring),
    ("monitoring low above high", _monitor(low=50), "mission.json", "$.pus.monitoring[0]",
     "low above high", install_monitoring),
    ("monitoring PMON twice", mission(lambda d: d["pus"]["monitoring"].append(
     dict(d["pus"]["monitoring"][0], low=10))), "mission.json", "$.pus.monitoring[1].pmon",
     "PMON 1 is also pus.monitoring[0]'s", install_monitoring),
    ("monitoring a raw limit beyond the type", _add_monitor({"pmon": 2, "parameter":
     "CpduA.health", "low": 0, "high": 300}), "mission.json", "$.pus.monitoring[1]",
     "raw 300, which uint8 cannot hold", install_monitoring),
    ("monitoring a string", _add_monitor({"pmon": 2, "parameter": "Software.version", "low": 0,
     "high": 3}), "mission.json", "$.pus.monitoring[1].parameter",
     "expected a numeric parameter", install_monitoring),
    ("structure beyond the largest packet", sdb(_big_structure), "sdb.json",
     "$.housekeeping[4].parameters", "expected at most 65507", report_structures),
    ("uint8 for a 64-bit value", _attr("Magnetorquer", "pulses", type="uint8"), "sdb.json",
     "$.components[0].attributes[10].type", "expected uint64", read_attributes),
    ("int16 for an unsigned 32-bit value", _attr("Magnetorquer", "on_time", type="int16"),
     "sdb.json", "$.components[0].attributes[8].type", "a u32 in the component",
     read_attributes),
    ("float32 for a 64-bit float", _attr("Magnetorquer", "energy", type="float32"), "sdb.json",
     "$.components[0].attributes[9].type", "expected float64", read_attributes),
    ("uint8 for a text", _attr("Magnetorquer", "label", type="uint8"), "sdb.json",
     "$.components[0].attributes[12].type", "expected string", read_attributes),
    ("uint8 for a node's 16-bit value", _attr("CpduA", "state_bits", type="uint8"), "sdb.json",
     "$.components[2].attributes[0].type", "a u16 in the component", read_attributes),
    ("attribute the component lacks", _extra("Magnetorquer", "attributes", {"name":
     "coil_voltage", "parameter": 399, "type": "float32"}), "sdb.json",
     "$.components[0].attributes[13].name", "Magnetorquer has no attribute coil_voltage",
     read_attributes),
    ("writable attribute the component only reads", _attr("Magnetorquer", "coil_temp",
     writable=True), "sdb.json", "$.components[0].attributes[4].writable", "read-only",
     read_attributes),
    ("event the component lacks", _extra("Magnetorquer", "events", {"name": "overheated",
     "id": 499, "severity": "high"}), "sdb.json", "$.components[0].events[2].name",
     "Magnetorquer has no event overheated", read_events),
    ("default beyond the calibration", _attr("Magnetorquer", "coil_temp", default=-400),
     "sdb.json", "$.components[0].attributes[4].default", "outside the calibration's points",
     read_defaults),
    ("time-driven component without its period", mission(lambda d: d["components"]
     ["Attitude"].pop("period")), "mission.json", "$.components.Attitude.period",
     "Attitude has tick(now) but no period", build_components),
    ("period for a component without tick", mission(lambda d: d["components"]["Magnetorquer"]
     .update(period=1)), "mission.json", "$.components.Magnetorquer.period",
     "Magnetorquer has no tick(now)", build_components),
    ("power-cycle node without power_cycle", _no_power_cycle, "mission.json",
     "$.platform.power_cycle.component", "no operation power_cycle(line, off_ms)",
     power_cycle_operation),
]  # fmt: skip


def test_the_corpus_holds_at_least_40_mistakes():
    assert len(MISTAKES) + len(IN_FLIGHT) >= 40


@pytest.fixture
def aurora(tmp_path):
    dest = tmp_path / "mission"
    shutil.copytree(AURORA, dest, ignore=shutil.ignore_patterns("__pycache__"))
    return str(dest)


@pytest.fixture
def sample_copy(tmp_path):
    dest = tmp_path / "mission"
    shutil.copytree(sample.MISSION_DIR, dest)
    return str(dest)


def test_the_unspoilt_folders_pass_and_fly():
    for folder in (AURORA, sample.MISSION_DIR):
        assert check(os.path.join(folder, "mission.json"))[1] == []
    for witness in {m[-1] for m in IN_FLIGHT}:
        witness(AURORA)  # the OBC's code accepts what the check accepts


@pytest.mark.parametrize("name,spoil,file,path,text,witness", IN_FLIGHT,
                         ids=[m[0] for m in IN_FLIGHT])  # fmt: skip
def test_a_mistake_that_would_fly_is_refused_by_check_and_serve_alike(
    aurora, tmp_path, monkeypatch, name, spoil, file, path, text, witness
):
    spoil(aurora)
    with pytest.raises((ConfigError, KeyError, ValueError, AttributeError, PermissionError)):
        witness(aurora)  # without the check, the OBC's own code fails here
    monkeypatch.chdir(tmp_path)
    _, problems = check(os.path.join(aurora, "mission.json"))
    lines = [str(p) for p in problems]
    assert len(lines) == 1, lines
    assert lines[0].startswith(os.path.join("mission", file) + ": " + path + ": "), lines
    assert text in lines[0] and "; expected " in lines[0], lines
    r = subprocess.run(OBSW + ["obc", "serve", aurora, "--state", str(tmp_path / "state")],
                       env=ENV, capture_output=True, text=True, timeout=BOUND)  # fmt: skip
    assert r.returncode == 2, r.stdout + r.stderr
    assert r.stderr.splitlines() == lines
    assert not (tmp_path / "state").exists()


@pytest.mark.parametrize("name,spoil,file,text", MISTAKES, ids=[m[0] for m in MISTAKES])
def test_check_says_what_serve_says(sample_copy, tmp_path, monkeypatch, name, spoil, file, text):
    """The mistakes already refused: the check's lines are those serve stops with
    (``test_mission_check`` runs serve on each)."""
    spoil(sample_copy)
    monkeypatch.chdir(tmp_path)
    _, problems = check(os.path.join(sample_copy, "mission.json"))
    assert len(problems) == 1, problems
    line = str(problems[0])
    assert line.startswith(os.path.join("mission", file) + ": ") and text in line, line


def test_a_database_given_as_the_mission_names_the_mission_folder(sample_copy, tmp_path):
    db = os.path.join(sample_copy, "sdb.json")
    before = open(db).read()
    for action in (["obc", "serve", db], ["obc", "config", db], ["mission", "check", db]):
        r = subprocess.run(OBSW + action, env=ENV, capture_output=True, text=True,
                           timeout=BOUND, cwd=str(tmp_path))  # fmt: skip
        assert r.returncode == 2, action
        assert r.stderr.splitlines() == [
            "mission/sdb.json: $: a spacecraft database, not a mission file; expected the "
            "mission folder mission (whose mission file names this database)"
        ], r.stderr
    r = subprocess.run(OBSW + ["mission", "upgrade", db], env=ENV, capture_output=True,
                       text=True, timeout=BOUND)  # fmt: skip
    assert r.returncode == 2 and "not a mission file" in r.stderr
    assert open(db).read() == before  # upgrade left it as it was
