"""The XTCE generated from the spacecraft database, the Yamcs instance, and Yamcs' own check."""

import json
import os
import pathlib
import xml.etree.ElementTree as ET

import pytest
from obsw_host.cli import main
from obsw_host.sample import SDB_PATH
from obsw_host.yamcs import database, server
from obsw_host.yamcs.instance import write_instance
from obsw_host.yamcs.xtce import event_templates, generate
from obsw_host.yamcs.xtce_types import XtceTypeError

ROOT = str(pathlib.Path(__file__).resolve().parents[2])
NS = {"x": "http://www.omg.org/spec/XTCE/20180204"}
X = NS["x"]


def extended_db(tmp_path):
    """The sample database plus a calibrated parameter (polynomial) and a spline."""
    with open(SDB_PATH) as f:
        doc = json.load(f)
    for p in doc["parameters"]:
        if p["name"] == "nav.distance":
            p["calibration"] = {"polynomial": [0, 0.001]}
            p["unit"] = "km"
        if p["name"] == "pus.failed":
            p["calibration"] = {"spline": [[0, 0], [10, 1], [100, 2]]}
            p["limits"] = {"warning": [None, 1.5]}
    path = tmp_path / "sdb.json"
    path.write_text(json.dumps(doc))
    return str(path)


@pytest.fixture(scope="module")
def xtce():
    sc = database.load(SDB_PATH)
    return sc, ET.fromstring(generate(sc))


def systems(root):
    out = {}

    def walk(ss, path):
        out[path] = ss
        for child in ss.findall("x:SpaceSystem", NS):
            walk(child, path + "/" + child.get("name"))

    walk(root, "/" + root.get("name"))
    return out


def containers(root):
    return {c.get("name"): c for c in root.iter("{%s}SequenceContainer" % NS["x"])}


def commands(root):
    out = {}
    for path, ss in systems(root).items():
        for c in ss.findall("x:CommandMetaData/x:MetaCommandSet/x:MetaCommand", NS):
            out[path + "/" + c.get("name")] = c
    return out


def test_every_housekeeping_structure_has_its_parameters_in_order(xtce):
    sc, root = xtce
    found = containers(root)
    for st in sc.structures:
        c = found["hk_%d" % st.sid]
        refs = [e.get("parameterRef") for e in c.findall("x:EntryList/x:ParameterRefEntry", NS)]
        expected = ["/obsw-demo/" + "/".join(sc.params[p].path) for p in st.parameters]
        assert refs == expected
        comparisons = c.findall(".//x:Comparison", NS)
        assert [(x.get("parameterRef"), x.get("value")) for x in comparisons] == [
            ("/obsw-demo/hk_structure_id", str(st.sid))
        ]


def test_parameters_carry_types_units_and_limits(xtce):
    sc, root = xtce
    panel = systems(root)["/obsw-demo/SolarPanel"]
    types = {t.get("name"): t for t in panel.find("x:TelemetryMetaData/x:ParameterTypeSet", NS)}
    speed = types["speed_t"]
    assert speed.tag.endswith("FloatParameterType")
    assert speed.find("x:UnitSet/x:Unit", NS).text == "deg/s"
    assert speed.find("x:FloatDataEncoding", NS).get("sizeInBits") == "32"
    ranges = speed.find("x:DefaultAlarm/x:StaticAlarmRanges", NS)
    assert ranges.find("x:WarningRange", NS).attrib == {"minInclusive": "1", "maxInclusive": "10"}
    assert ranges.find("x:CriticalRange", NS).attrib == {
        "minInclusive": "0.5",
        "maxInclusive": "15",
    }
    assert types["is_deployed_t"].tag.endswith("BooleanParameterType")


def test_calibrations_become_calibrators(tmp_path):
    sc = database.load(extended_db(tmp_path))
    root = ET.fromstring(generate(sc))
    nav = systems(root)["/obsw-demo/nav"]
    t = nav.find("x:TelemetryMetaData/x:ParameterTypeSet/x:FloatParameterType", NS)
    assert t.get("name") == "distance_t"
    terms = t.findall(".//x:PolynomialCalibrator/x:Term", NS)
    assert [(x.get("coefficient"), x.get("exponent")) for x in terms] == [
        ("0.0", "0"),
        ("0.001", "1"),
    ]
    assert t.find("x:IntegerDataEncoding", NS).get("sizeInBits") == "32"
    pus = systems(root)["/obsw-demo/pus"]
    points = pus.findall(".//x:SplineCalibrator/x:SplinePoint", NS)
    assert len(points) == 3


def test_events_have_containers_and_templates(xtce):
    sc, root = xtce
    found = containers(root)
    templates = {t["eventId"]: t["template"] for t in event_templates(sc)}
    for e in sc.events.values():
        label = e.qualified.replace(".", "_")
        c = found["event_" + label]
        refs = [x.get("parameterRef") for x in c.findall(".//x:ParameterRefEntry", NS)]
        assert len(refs) == len(e.fields)
        assert templates[label].startswith(e.qualified)
    enum = root.find(".//x:EnumeratedParameterType[@name='event_id_t']", NS)
    labels = {x.get("value"): x.get("label") for x in enum.iter("{%s}Enumeration" % NS["x"])}
    assert labels["1"] == "SolarPanel_angle_reached"


def test_every_service_has_its_commands(xtce):
    sc, root = xtce
    cmds = commands(root)
    pus = "/obsw-demo/PUS/"
    for name in (
        "ping",
        "connection_test",
        "hk_enable",
        "hk_disable",
        "hk_one_shot",
        "hk_interval",
        "event_enable",
        "event_disable",
        "schedule_enable",
        "schedule_reset",
        "monitoring_enable",
        "monitor_enable",
        "parameters_report",
        "obcp_load",
        "obcp_activate",
        "obcp_abort",
        "file_create",
        "file_copy",
    ):
        assert pus + name in cmds, name
    # service 8: one command per function, its typed arguments after their ids
    set_angle = cmds["/obsw-demo/SolarPanel/set_angle"]
    entries = [
        (e.tag.split("}")[1], e.get("name") or e.get("argumentRef"))
        for e in set_angle.find("x:CommandContainer/x:EntryList", NS)
    ]
    assert entries == [
        ("FixedValueEntry", "function"),
        ("FixedValueEntry", "n"),
        ("FixedValueEntry", "id_angle"),
        ("ArgumentRefEntry", "angle"),
    ]
    assert "/obsw-demo/SolarPanel/deploy" in cmds
    # service 20: a set command for each writable parameter only, its range from the database
    for p in sc.params.values():
        name = "/obsw-demo/%s/set_%s" % ("/".join(p.path[:-1]), p.path[-1])
        is_set = name in cmds and cmds[name].get("shortDescription", "").startswith("TC[20,3]")
        assert is_set == p.writable
    speed_type = root.find(".//x:FloatArgumentType[@name='set_speed_value_t']", NS)
    assert speed_type.find("x:ValidRangeSet/x:ValidRange", NS).attrib == {
        "minInclusive": "0.1",
        "maxInclusive": "20",
    }


def test_command_verifiers_follow_service_1(xtce):
    sc, root = xtce
    base = commands(root)["/obsw-demo/pus_tc"]
    verifiers = base.find("x:VerifierSet", NS)
    stages = []
    for v in verifiers:
        text = v.find(".//x:AlgorithmText", NS).text
        stages.append((v.tag.split("}")[1], text.split("stage: ")[1].split(",")[0]))
        inputs = [i.get("inputName") for i in v.iter("{%s}InputParameterInstanceRef" % NS["x"])]
        assert inputs[:5] == ["sentApid", "sentSeq", "rcvdApid", "rcvdSeq", "reportSubType"]
    assert stages == [
        ("AcceptedVerifier", "1"),
        ("ExecutionVerifier", "3"),
        ("CompleteVerifier", "7"),
    ]
    found = containers(root)
    for name in ("verification", "acceptance_failure", "start_failure", "completion_failure"):
        assert name in found
    assert "check_transition" in found  # service 12: every transition of a report


def test_unsupported_types_raise_typed_errors(tmp_path):
    with open(SDB_PATH) as f:
        doc = json.load(f)
    doc["parameters"].append({"name": "pus.bits", "id": 120, "type": [6, 12]})  # a bit string
    path = tmp_path / "sdb.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(XtceTypeError, match="PTC 6"):
        generate(database.load(str(path)))


def test_octets_are_binary_after_their_length(tmp_path):
    """PTC 7: a variable octet string is binary data whose size is the length before it (in
    containers and in the TC[20,3] that sets it); a fixed one is that many octets."""
    with open(SDB_PATH) as f:
        doc = json.load(f)
    doc["parameters"] += [
        {"name": "pus.blob", "id": 120, "type": "octets", "writable": True},
        {"name": "pus.key", "id": 121, "type": [7, 4]},
    ]
    doc["housekeeping"].append({"sid": 42, "interval": 1, "parameters": ["pus.blob", "pus.key"]})
    path = tmp_path / "sdb.json"
    path.write_text(json.dumps(doc))
    root = ET.fromstring(generate(database.load(str(path))))
    types = {t.get("name"): t for t in root.iter("{%s}BinaryParameterType" % X)}
    size = types["blob_t"].find(".//x:DynamicValue/x:ParameterInstanceRef", NS)
    assert size.get("parameterRef").endswith("/pus/blob_length")
    assert types["key_t"].find(".//x:FixedValue", NS).text == "32"
    hk = [c for c in root.iter("{%s}SequenceContainer" % X) if c.get("name") == "hk_42"][0]
    refs = [e.get("parameterRef").split("/")[-1] for e in hk.iter("{%s}ParameterRefEntry" % X)]
    assert refs == ["blob_length", "blob", "key"]
    cmd = [c for c in root.iter("{%s}MetaCommand" % X) if c.get("name") == "set_blob"][0]
    assert [a.get("name") for a in cmd.iter("{%s}Argument" % X)] == ["length", "value"]


def test_cli_writes_the_xtce_and_the_instance(tmp_path, capsys):
    assert main(["yamcs", "xtce", SDB_PATH, "-o", str(tmp_path / "m.xml")]) == 0
    assert ET.parse(str(tmp_path / "m.xml")).getroot().get("name") == "obsw-demo"
    assert main(["yamcs", "config", str(tmp_path / "y"), "--mode", "frames"]) == 0
    text = (tmp_path / "y" / "etc" / "yamcs.sample-spacecraft.yaml").read_text()  # the mission
    assert "UdpTcFrameLink" in text and "useCop1: true" in text
    assert '"CRC-16-CCIIT"' in text and "implicitPField: 30" in text  # CUC 4+2, TAI epoch
    server_yaml = (tmp_path / "y" / "etc" / "yamcs.yaml").read_text()
    assert 'address: "127.0.0.1"' in server_yaml


@pytest.mark.skipif(server.missing() is not None, reason=str(server.missing()))
def test_yamcs_check_accepts_configuration_and_mdb(tmp_path):
    # both link modes (one instance each) and a database with calibrations, one Yamcs run
    sc = database.load(extended_db(tmp_path))
    folder = str(tmp_path / "yamcs")
    write_instance(
        folder, sc, instances={"packets": ("packets", None), "frames": ("frames", None)}
    )
    ok, output = server.check(folder)
    assert ok, output[-3000:]
    assert "SEVERE" not in output


@pytest.mark.parametrize("mission", ["sample", "aurora", "new"])
def test_every_example_and_a_new_mission_generate_xtce(mission, tmp_path):
    folder = os.path.join(ROOT, "examples", mission)
    if mission == "new":
        folder = str(tmp_path / "lynx")
        assert main(["mission", "new", "lynx", "--dir", folder]) == 0
    out = tmp_path / "m.xml"
    assert main(["yamcs", "xtce", "--mission", folder, "-o", str(out)]) == 0
    assert ET.parse(str(out)).getroot().find("x:TelemetryMetaData", NS) is not None


@pytest.mark.skipif(server.missing() is not None, reason=str(server.missing()))
def test_yamcs_check_accepts_aurora(tmp_path):
    """aurora differs from the sample in every tailorable way (octets among its types)."""
    folder = str(tmp_path / "yamcs")
    assert (
        main(["yamcs", "config", "--mission", os.path.join(ROOT, "examples", "aurora"), folder])
        == 0
    )
    ok, output = server.check(folder)
    assert ok, output[-3000:]
    assert "SEVERE" not in output
