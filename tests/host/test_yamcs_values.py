"""Raw and engineering values in the XTCE: enumerated parameter types, calibrators of every shape
the database takes, set commands in engineering units, monitoring defaults converted to raw,
functional monitoring and parameter definitions; Yamcs' own check accepts the result."""

import json
import xml.etree.ElementTree as ET

from obsw_host.sample import SDB_PATH
from obsw_host.yamcs import database, server
from obsw_host.yamcs.instance import write_instance
from obsw_host.yamcs.xtce import generate
from test_yamcs_config import NS, commands, containers, systems


def values_db(tmp_path):
    """The sample database with labelled, XTCE-shaped, stepwise and linear calibrations."""
    with open(SDB_PATH) as f:
        doc = json.load(f)
    for comp in doc["components"]:
        for a in comp.get("attributes", ()):
            if (comp["name"], a["name"]) == ("SolarPanel", "speed"):
                a["calibration"] = {"polynomial": [{"coefficient": 2, "exponent": 1}]}
            if (comp["name"], a["name"]) == ("CpduN", "health"):
                a["enumeration"] = [{"value": 0, "label": "OK"}, {"value": 1, "label": "FAULT"}]
            if (comp["name"], a["name"]) == ("CpduN", "state_bits"):
                a["calibration"] = {"spline": [[0, 0], [100, 10]], "order": 0}
                a["limits"] = {"critical": [2, 8]}
    path = tmp_path / "sdb.json"
    path.write_text(json.dumps(doc))
    return str(path)


def test_enumerations_calibrators_and_engineering_commands(tmp_path):
    root = ET.fromstring(generate(database.load(values_db(tmp_path))))
    cpdu = systems(root)["/obsw-demo/CpduN"]
    enum = cpdu.find("x:TelemetryMetaData/x:ParameterTypeSet/x:EnumeratedParameterType", NS)
    labels = [(e.get("value"), e.get("label")) for e in enum.iter("{%s}Enumeration" % NS["x"])]
    assert (enum.get("name"), labels) == ("health_t", [("0", "OK"), ("1", "FAULT")])
    spline = cpdu.find(".//x:SplineCalibrator", NS)
    assert spline.get("order") == "0"
    panel = systems(root)["/obsw-demo/SolarPanel"]
    terms = panel.findall(".//x:ParameterTypeSet//x:PolynomialCalibrator/x:Term", NS)
    assert [(t.get("coefficient"), t.get("exponent")) for t in terms] == [
        ("0.0", "0"),
        ("2.0", "1"),
    ]
    # the set command takes deg/s, Yamcs reverses the linear calibration and checks the range
    arg = panel.find(".//x:ArgumentTypeSet/x:FloatArgumentType[@name='set_speed_value_t']", NS)
    assert arg.find(".//x:PolynomialCalibrator", NS) is not None
    assert arg.find(".//x:ValidRange", NS).get("maxInclusive") == "20"
    # the limit check's default limits are raw: 2..8 on a stepwise calibration has no inverse
    monitor = commands(root)["/obsw-demo/CpduN/monitor_state_bits"]
    initial = {
        a.get("name"): a.get("initialValue") for a in monitor.iter("{%s}Argument" % NS["x"])
    }
    assert initial["low"] is None and initial["high"] is None


def test_functional_monitoring_and_definitions_in_the_mdb(tmp_path):
    root = ET.fromstring(generate(database.load(SDB_PATH)))
    names = set(commands(root))
    for name in (
        "fmon_function_enable",
        "fmon_function_disable",
        "fmon_enable",
        "fmon_disable",
        "fmon_protect",
        "fmon_unprotect",
        "fmon_add_1",
        "fmon_add_4",
        "fmon_delete",
        "fmon_report",
        "fmon_status_report",
        "parameter_definitions_report",
        "parameter_define_raw",
        "parameter_define_object",
    ):
        assert "/obsw-demo/PUS/" + name in names
    for name in (
        "functional_status_report",
        "functional_definition_report",
        "parameter_definition_report",
    ):
        assert name in containers(root)
    # the monitor command of the sample's float parameter keeps its engineering limits
    monitor = commands(root)["/obsw-demo/SolarPanel/monitor_speed"]
    initial = {
        a.get("name"): a.get("initialValue") for a in monitor.iter("{%s}Argument" % NS["x"])
    }
    assert (initial["low"], initial["high"]) == ("0.5", "15")


def test_yamcs_accepts_the_values_mdb(tmp_path):
    sc = database.load(values_db(tmp_path))
    folder = str(tmp_path / "yamcs")
    write_instance(folder, sc, instances={"packets": ("packets", None)})
    ok, output = server.check(folder)
    assert ok, output[-3000:]
    assert "SEVERE" not in output
