"""The OBC's composition root: the topology of a mission, the unit registry, the PUS service
table, and mission components as plug-ins (the contract of ``obsw_host.obc.plugins``)."""

import json
import os

import pytest
from obsw_host.mission import config as obc_config
from obsw_host.obc import registry
from obsw_host.obc.plugins import Component, PluginError, component_for
from obsw_host.obc.topology import Topology
from obsw_host.pus.onboard import SERVICES
from obsw_host.sample import MISSION_DIR, MISSION_PATH
from test_obc_assembly import free_port

PLUGIN = """
from obsw.il.interface import DATA, Attribute, Interface, Operation

MAGNETORQUER = Interface(
    "Magnetorquer",
    0x61,
    [Attribute("dipole", 1, DATA, type="f32"), Operation("fire", 2, ("dipole",))],
)


class Torquer:
    def __init__(self, coils=1, limit=0.2):
        self.coils = coils
        self.limit = limit
        self.dipole = 0.0

    def fire(self, dipole):
        self.dipole = min(dipole, self.limit)
        return self.dipole
"""


def sample():
    with open(MISSION_PATH) as f:
        return json.load(f)


def mission(tmp_path, change=None, plugin=PLUGIN):
    """The sample with its paths made absolute, changed by ``change``, in ``tmp_path``."""
    doc = sample()
    base = os.path.dirname(MISSION_PATH)
    doc["sdb"] = os.path.join(base, doc["sdb"])
    doc["obcp"]["files"] = os.path.join(base, doc["obcp"]["files"])
    doc["state"] = str(tmp_path / "state")
    doc["pus"]["port"] = free_port()  # another OBC may run on this machine
    doc["cfdp"]["port"] = free_port()
    doc.update(change or {})
    (tmp_path / "magnetorquer.py").write_text(plugin)
    path = tmp_path / "mission.json"
    path.write_text(json.dumps(doc))
    return obc_config.load(str(path))


def test_every_registered_unit_kind_imports_and_has_the_unit_methods():
    for kind in registry.UNITS:
        cls = registry.unit_class(kind)
        for method in ("start", "stop", "alive"):
            assert callable(getattr(cls, method)), (kind, method)
    assert set(registry.KINDS) >= set(registry.WITH_PUS)


def test_the_sample_topology():
    topology = Topology(obc_config.load(MISSION_DIR)).check()
    (obc,) = topology.processes
    assert [label for label, _ in obc.units()] == ["pus", "spacecan"]
    assert [c.name for c in obc.components] == ["SolarPanel"]
    assert topology.process_of("SolarPanel") is obc
    assert topology.process_of("frames") is None
    names = [i.name for i in topology.interfaces()]
    assert names == ["SolarPanel", "CpduN", "CpduR", "OnboardTime", "Software", "Passes"]
    described = topology.describe()
    assert described["components"]["SolarPanel"]["module"] == "obsw_host.solar_panel"
    assert described["processes"]["obc"]["units"] == ["pus", "spacecan"]
    assert topology.pus_apid() == 10


def test_the_database_is_read_once(monkeypatch):
    import obsw_host.sample

    calls = []
    real = obsw_host.sample.load_sdb
    monkeypatch.setattr(obsw_host.sample, "load_sdb", lambda p: calls.append(p) or real(p))
    topology = Topology(obc_config.load(MISSION_DIR))
    topology.pus_apid()
    topology.equipments()
    topology.interfaces()
    assert len(calls) == 1


def test_one_service_table_gives_the_obc_every_service(tmp_path):
    from obsw_host.obc.assembly import ObcProcess

    numbers = [n for n, _, _ in SERVICES]
    assert len(numbers) == len(set(numbers))  # one entry per service
    every = [1, 2, 3, 4, 5, 6, 8, 9, 11, 12, 13, 14, 15, 17, 18, 19, 20, 21, 22, 23]
    assert sorted(numbers + [1]) == every  # 1 is the application process's own
    config = mission(tmp_path, {"processes": {"core": ["pus", "cfdp", "obcp"]}})
    process = ObcProcess(config, "core", out=lambda s: None)  # built, not started
    try:
        assert sorted(process.unit("pus").app.services) == every
    finally:
        process.stop()


def test_a_legacy_solar_panel_kind_is_the_plug_in():
    doc = sample()
    doc["processes"] = {"obc": ["pus", "solar_panel"]}
    del doc["components"]
    c = obc_config.MissionConfig(doc, MISSION_PATH)
    assert c.processes == {"obc": ["pus", "SolarPanel"]}
    assert Topology(c).components["SolarPanel"].module_ref == "obsw_host.solar_panel"


def test_a_plug_in_from_a_file_with_its_class_and_options(tmp_path):
    config = mission(tmp_path, {
        "processes": {"core": ["pus"], "adcs": ["Magnetorquer", "SolarPanel"]},
        "components": {
            "Magnetorquer": {"module": "magnetorquer.py", "class": "Torquer",
                             "options": {"coils": 3, "limit": 0.5}},
            "SolarPanel": {"module": "obsw_host.solar_panel"},
        },
    })  # fmt: skip
    topology = Topology(config).check()
    adcs = topology.process("adcs")
    assert adcs.units() == [("components", "component")]
    itf, impl = topology.components["Magnetorquer"].build()
    assert itf.name == "Magnetorquer" and impl.coils == 3
    assert impl.fire(2.0) == 0.5
    assert [i.name for i in topology.interfaces()][:2] == ["Magnetorquer", "SolarPanel"]


@pytest.mark.parametrize(
    "entry, key, words",
    [
        ({"module": "no_such_module_xyz"}, "components.Magnetorquer.module", "cannot import"),
        ({"module": "missing.py"}, "components.Magnetorquer.module", "no file"),
        ({"module": "obsw_host.solar_panel"}, "components.Magnetorquer.module", "SolarPanel"),
        ({"module": "magnetorquer.py"}, "components.Magnetorquer.class", "no class"),
        ({"module": "magnetorquer.py", "klass": "Torquer"}, "components.Magnetorquer", "klass"),
        ({"module": 5}, "components.Magnetorquer.module", "expected"),
        ({"module": "magnetorquer.py", "options": []}, "components.Magnetorquer.options", "obj"),
    ],
)
def test_a_component_that_cannot_be_used_is_a_config_error(tmp_path, entry, key, words):
    config = mission(tmp_path, {
        "processes": {"core": ["pus", "Magnetorquer"]},
        "components": {"Magnetorquer": entry},
    })  # fmt: skip
    with pytest.raises(obc_config.ConfigError) as e:
        Topology(config).check()
    assert e.value.key == key
    assert words in str(e.value)


def test_a_module_that_fails_to_load_says_why(tmp_path):
    config = mission(tmp_path, {
        "processes": {"core": ["pus", "Magnetorquer"]},
        "components": {"Magnetorquer": {"module": "magnetorquer.py", "class": "Torquer"}},
    }, plugin="import no_such_dependency_xyz\n")  # fmt: skip
    with pytest.raises(PluginError) as e:
        Topology(config).check()
    assert "ModuleNotFoundError" in str(e.value)


def test_wrong_options_fail_when_built(tmp_path):
    c = Component("Magnetorquer", {"module": "magnetorquer.py", "class": "Torquer",
                                   "options": {"voltage": 5}}, str(tmp_path))  # fmt: skip
    (tmp_path / "magnetorquer.py").write_text(PLUGIN)
    with pytest.raises(PluginError) as e:
        c.build()
    assert e.value.key == "components.Magnetorquer.options" and "voltage" in str(e.value)


def test_components_run_by_no_process_and_unknown_names(tmp_path):
    topology = Topology(mission(tmp_path, {
        "processes": {"core": ["pus"]},
        "components": {"Magnetorquer": {"module": "missing.py"}},
    })).check()  # fmt: skip
    assert topology.describe()["components"]["Magnetorquer"]["process"] is None
    assert [i.name for i in topology.interfaces()] == ["OnboardTime", "Software", "Passes"]
    with pytest.raises(obc_config.ConfigError) as e:
        mission(tmp_path, {"processes": {"core": ["pus", "Magnetorker"]}})
    assert e.value.key == "processes.core" and "Magnetorker" in str(e.value)


def test_a_component_outside_a_mission_is_named_by_its_interface():
    c = component_for("obsw_host.solar_panel")
    assert (c.name, c.class_name) == ("SolarPanel", "SolarPanel")
    itf, impl = c.build()
    assert itf.name == "SolarPanel" and impl.angle == 0.0


def test_the_plug_in_example_is_the_one_the_documentation_shows():
    import re

    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    with open(os.path.join(root, "docs", "topology.md")) as f:
        shown = re.findall(r"```python\n(.*?)```", f.read(), re.S)[0]
    with open(os.path.join(root, "examples", "torquer.py")) as f:
        assert shown in f.read()
    c = component_for(os.path.join(root, "examples", "torquer.py"), cls="Torquer")
    itf, impl = c.build()
    assert itf.name == "Magnetorquer" and impl.limit == 0.2
