"""Realistic mistakes in a mission folder, each run through the real `obsw obc serve`: it ends
within seconds with exactly one line naming the file, the JSON path and what was expected,
exit status 2, no traceback, and nothing started (no state folder, no process, no power
cycle). Every mistake is made in a copy of the sample mission (examples/sample)."""

import json
import os
import shutil
import subprocess
import sys

import pytest
from obsw_host import sample
from obsw_host.mission import MissionError, locate
from obsw_host.mission.check import check, load
from obsw_host.mission.upgrade import upgrade

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
OBSW = [sys.executable, "-m", "obsw_host.cli"]
ENV = dict(
    os.environ,
    PYTHONPATH=os.pathsep.join([os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]),
)
ENV.pop("OBSW_MISSION", None)
BOUND = 20.0  # seconds: a refused start must end well within this


def edit(folder, name, change):
    """Apply ``change(doc)`` to JSON file ``name`` of ``folder``."""
    path = os.path.join(folder, name)
    with open(path) as f:
        doc = json.load(f)
    change(doc)
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)


def component(doc, name):
    return next(c for c in doc["components"] if c["name"] == name)


def attribute(doc, comp, name):
    return next(a for a in component(doc, comp)["attributes"] if a["name"] == name)


def sdb(change):
    return lambda folder: edit(folder, "sdb.json", change)


def mission(change):
    return lambda folder: edit(folder, "mission.json", change)


def write(name, text):
    def apply(folder):
        with open(os.path.join(folder, name), "w") as f:
            f.write(text)

    return apply


def _set(obj, key, value):
    obj[key] = value


def _dup_component(d):
    d["components"].append({"name": "SolarPanel", "attributes": []})


def _unknown_key(d):
    a = attribute(d, "SolarPanel", "speed")
    a["writeable"] = a.pop("writable")


def _missing_type(d):
    del attribute(d, "SolarPanel", "angle")["type"]


def _missing_event_id(d):
    del component(d, "SolarPanel")["events"][0]["id"]


def _dup_attribute(d):
    component(d, "SolarPanel")["attributes"].append(
        {"name": "angle", "parameter": 9, "type": "float32"}
    )


def _dup_function_id(d):
    d["functions"][1]["id"] = 1


def _dup_node_id(d):
    d["nodes"][1]["node_id"] = 10


def _dup_sid(d):
    d["housekeeping"][1]["sid"] = 1


def _dup_prefix(d):
    d["filestores"][1]["prefix"] = "SAT"


def _bad_pair(d):
    attribute(d, "CpduN", "health")["limits"] = {"warning": [10, 5]}


def _default_type(d):
    attribute(d, "SolarPanel", "speed")["default"] = "fast"


def _dup_operation_argument(d):
    component(d, "SolarPanel")["operations"] = [
        {"name": "set_angle", "arguments": [{"name": "angle"}, {"name": "angle"}]}
    ]


def _object_outside(d):
    d["memories"][0]["objects"] = [
        {"id": 1, "name": "header", "size": 64},
        {"id": 2, "name": "table", "offset": 65000, "size": 1024},
    ]


def _obcp_alone(d):
    d["processes"]["obc"].remove("obcp")
    d["processes"]["x"] = ["obcp"]


def _twice(folder):
    path = os.path.join(folder, "sdb.json")
    with open(path) as f:
        text = f.read()
    with open(path, "w") as f:
        f.write(text.replace('"mission":', '"mission": "again",\n  "mission":', 1))


# (name, how the folder is spoiled, file of the line, text the line must contain)
MISTAKES = [
    ("duplicate component", sdb(_dup_component), "sdb.json",
     "component SolarPanel declared twice"),
    ("duplicate attribute", sdb(_dup_attribute), "sdb.json", "SolarPanel.angle declared twice"),
    ("duplicate parameter id",
     sdb(lambda d: _set(attribute(d, "CpduN", "health"), "parameter", 20)),
     "sdb.json", "parameter id 20 is also CpduN.state_bits's"),
    ("duplicate event id",
     sdb(lambda d: _set(component(d, "SolarPanel")["events"][1], "id", 1)),
     "sdb.json", "event id 1 is also SolarPanel.angle_reached's"),
    ("duplicate function id", sdb(_dup_function_id), "sdb.json", "$.functions[1].id"),
    ("duplicate APID", sdb(lambda d: _set(d["apids"], "frames", 10)), "sdb.json",
     "$.apids.frames: APID 10 is also pus's"),
    ("duplicate node id", sdb(_dup_node_id), "sdb.json", "$.nodes[1].node_id"),
    ("duplicate housekeeping sid", sdb(_dup_sid), "sdb.json", "$.housekeeping[1].sid"),
    ("duplicate filestore prefix", sdb(_dup_prefix), "sdb.json", "$.filestores[1].prefix"),
    ("unknown type",
     sdb(lambda d: _set(attribute(d, "SolarPanel", "angle"), "type", "float23")),
     "sdb.json", "did you mean 'float32'?"),
    ("missing type", sdb(_missing_type), "sdb.json", "missing key 'type'"),
    ("missing event id", sdb(_missing_event_id), "sdb.json", "missing key 'id'"),
    ("APID out of range", sdb(lambda d: _set(d["apids"], "pus", 4096)), "sdb.json",
     "$.apids.pus: 4096 is out of range; expected an integer from 0 to 2047"),
    ("APID a string", sdb(lambda d: _set(d["apids"], "pus", "10")), "sdb.json",
     '$.apids.pus: "10" is a string; expected an integer'),
    ("range low above high",
     sdb(lambda d: _set(attribute(d, "SolarPanel", "speed"), "range", [20, 0.1])),
     "sdb.json", "low above high"),
    ("range beyond the type",
     sdb(lambda d: _set(attribute(d, "CpduN", "health"), "range", [0, 300])),
     "sdb.json", "exceeds type uint8"),
    ("limits low above high", sdb(_bad_pair), "sdb.json", "limits.warning"),
    ("critical limits inside warning",
     sdb(lambda d: _set(attribute(d, "SolarPanel", "speed"), "limits",
                        {"warning": [0.5, 15], "critical": [1, 10]})),
     "sdb.json", "expected the critical limits around the warning ones"),
    ("limits a number",
     sdb(lambda d: _set(attribute(d, "SolarPanel", "speed"), "limits", 10)),
     "sdb.json", "$.components[0].attributes[1].limits: 10 is an integer; expected an object"),
    ("calibration of unknown shape",
     sdb(lambda d: _set(attribute(d, "SolarPanel", "angle"), "calibration", {"poly": [0, 1]})),
     "sdb.json", "calibration"),
    ("default of the wrong type", sdb(_default_type), "sdb.json",
     "$.components[0].attributes[1].default"),
    ("unknown key writeable", sdb(_unknown_key), "sdb.json", "did you mean 'writable'?"),
    ("unknown severity",
     sdb(lambda d: _set(d["events"][0], "severity", "critical")),
     "sdb.json", "$.events[0].severity"),
    ("function naming no operation",
     sdb(lambda d: _set(d["functions"][0], "name", "SolarPanel.fold")),
     "sdb.json", "SolarPanel has no operation fold"),
    ("housekeeping naming no parameter",
     sdb(lambda d: _set(d["housekeeping"][0]["parameters"], 0, "SolarPanel.angel")),
     "sdb.json", "did you mean 'SolarPanel.angle'?"),
    ("missing node file",
     sdb(lambda d: _set(d["nodes"][1], "definition", "nodes/cpdu_r.json")),
     "sdb.json", "$.nodes[1].definition: file \"nodes/cpdu_r.json\" not found"),
    ("node file with a bad encoding",
     write("nodes/cpdu.json", json.dumps({"parameters": [{"parameter_id": 1,
           "parameter_name": "x", "encoding": "u17", "value": 0}], "functions": [],
           "housekeeping_reports": []})),
     "nodes/cpdu.json", "u17"),
    ("invalid JSON in the database", write("sdb.json", '{"mission": "x",\n "apids": {},}\n'),
     "sdb.json", "not valid JSON"),
    ("invalid JSON in the mission file", write("mission.json", '{"format": 2\n "name": "x"}'),
     "mission.json", "not valid JSON"),
    ("key given twice", _twice, "sdb.json", "key 'mission' given twice"),
    ("unknown process kind",
     mission(lambda d: _set(d["processes"]["obc"], 4, "SolarPanl")),
     "mission.json", "did you mean 'SolarPanel'?"),
    ("unknown key in a section",
     mission(lambda d: _set(d["platform"], "heartbeet", 0.5)),
     "mission.json", "$.platform.heartbeet: unknown key"),
    ("component module not found",
     mission(lambda d: _set(d["components"]["SolarPanel"], "module", "components/panel.py")),
     "mission.json", "$.components.SolarPanel.module"),
    ("component class not in its module",
     mission(lambda d: _set(d["components"]["SolarPanel"], "class", "Panel")),
     "mission.json", "$.components.SolarPanel.class: obsw_host.solar_panel has no class 'Panel'"),
    ("kind in two processes",
     mission(lambda d: _set(d["processes"], "spare", ["spacecan"])),
     "mission.json", "$.processes.spare[0]: \"spacecan\" already runs in process \"obc\""),
    ("obcp away from pus",
     mission(_obcp_alone),
     "mission.json", "$.processes.x: runs obcp without pus"),
    ("operation argument given twice", sdb(_dup_operation_argument), "sdb.json",
     "$.components[0].operations[0].arguments[1].name: argument \"angle\" given twice"),
    ("memory object outside its area", sdb(_object_outside), "sdb.json",
     "$.memories[0].objects[1]: octets 65000..66023 outside the memory's 65536"),
    ("missing database file", mission(lambda d: _set(d, "sdb", "db.json")), "mission.json",
     "$.sdb: file \"db.json\" not found"),
    ("power cycle through no node",
     mission(lambda d: _set(d["platform"]["power_cycle"], "component", "CpduNominal")),
     "mission.json", "did you mean 'CpduN'?"),
    ("procedure naming no activity",
     write("procedures/bad.plt", "procedure\n  main\n    initiate and confirm fold of "
           "SolarPanel;\n  end main\nend procedure\n"),
     "procedures/bad.plt", "line 3 column"),
]  # fmt: skip


@pytest.fixture
def folder(tmp_path):
    dest = tmp_path / "mission"
    shutil.copytree(sample.MISSION_DIR, dest)
    return str(dest)


def test_the_sample_passes():
    m, problems = check(locate(sample.MISSION_DIR))
    assert problems == []
    assert sorted(m.interfaces) == [
        "CpduN",
        "CpduR",
        "OnboardTime",
        "Passes",
        "Software",
        "SolarPanel",
    ]
    assert m.sdb.apid("pus") == 10


def test_at_least_23_mistakes():
    assert len(MISTAKES) >= 23


@pytest.mark.parametrize("name,spoil,file,text", MISTAKES, ids=[m[0] for m in MISTAKES])
def test_a_mistake_stops_obc_serve_in_one_line(
    folder, tmp_path, monkeypatch, name, spoil, file, text
):
    spoil(folder)
    monkeypatch.chdir(tmp_path)
    said = [str(p) for p in check(os.path.join(folder, "mission.json"))[1]]
    state = tmp_path / "state"
    r = subprocess.run(
        OBSW + ["obc", "serve", folder, "--state", str(state)],
        env=ENV, capture_output=True, text=True, timeout=BOUND, cwd=str(tmp_path),
    )  # fmt: skip
    lines = [x for x in (r.stdout + r.stderr).splitlines() if x.strip()]
    assert r.returncode == 2, lines
    assert len(lines) == 1, lines
    line = lines[0]
    assert line.startswith(os.path.join("mission", file) + ": "), line
    assert text in line, line
    assert "; expected " in line or "line " in line, line
    assert "Traceback" not in line
    assert lines == said  # `obsw mission check` says the same
    assert not state.exists()  # no process started: none made its state folder


def test_every_problem_is_listed(folder):
    sdb(_unknown_key)(folder)
    sdb(_dup_sid)(folder)
    mission(lambda d: _set(d["platform"], "heartbeet", 0.5))(folder)
    with pytest.raises(MissionError) as e:
        load(folder)
    texts = [str(p) for p in e.value.problems]
    assert len(texts) == 3, texts
    assert [t.split(":")[0] for t in texts] == [
        os.path.join(folder, "mission.json"),
        os.path.join(folder, "sdb.json"),
        os.path.join(folder, "sdb.json"),
    ]


def test_mission_check_lists_every_problem_and_exits_2(folder):
    sdb(_unknown_key)(folder)
    sdb(_dup_sid)(folder)
    r = subprocess.run(OBSW + ["mission", "check", folder], env=ENV, capture_output=True,
                       text=True, timeout=BOUND)  # fmt: skip
    assert r.returncode == 2
    lines = r.stderr.splitlines()
    assert len(lines) == 2 and all("sdb.json: $." in x for x in lines), lines
    r = subprocess.run(OBSW + ["mission", "check", sample.MISSION_DIR], env=ENV,
                       capture_output=True, text=True, timeout=BOUND)  # fmt: skip
    assert r.returncode == 0 and ": ok (sample-spacecraft;" in r.stdout


def test_no_mission_named_is_one_line(tmp_path):
    r = subprocess.run(OBSW + ["obc", "serve"], env=ENV, capture_output=True, text=True,
                       timeout=BOUND, cwd=str(tmp_path))  # fmt: skip
    assert r.returncode == 2
    assert r.stderr.count("\n") == 1 and "no mission named" in r.stderr
    assert "OBSW_MISSION" in r.stderr


def test_locate_from_env_and_from_a_parent_folder(folder, monkeypatch):
    sub = os.path.join(folder, "procedures")
    monkeypatch.chdir(sub)
    monkeypatch.delenv("OBSW_MISSION", raising=False)
    assert locate() == os.path.join(folder, "mission.json")
    monkeypatch.setenv("OBSW_MISSION", sample.MISSION_DIR)
    assert locate() == sample.MISSION_PATH
    assert locate(folder + "/mission.json") == os.path.join(folder, "mission.json")


def test_a_format_1_file_is_refused_and_upgraded(tmp_path):
    old = {
        "name": "old",
        "sdb": os.path.join(sample.MISSION_DIR, "sdb.json"),
        "processes": {"obc": ["pus", "solar_panel"]},
        "pus": {"apid": 10},
    }
    path = tmp_path / "old.json"
    path.write_text(json.dumps(old))
    _, problems = check(str(path))
    assert len(problems) == 1 and "obsw mission upgrade" in str(problems[0])
    new, changes = upgrade(old)
    assert new["format"] == 2
    assert new["processes"] == {"obc": ["pus", "SolarPanel"]}
    assert new["components"] == {"SolarPanel": {"module": "obsw_host.solar_panel"}}
    r = subprocess.run(OBSW + ["mission", "upgrade", str(path)], env=ENV, capture_output=True,
                       text=True, timeout=BOUND)  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert check(str(path))[1] == []
