"""XTCE for the types of services 2, 3, 9 and 14: a command for each TC an operator sends,
laid out as the service user packs it, and a container for each report."""

import xml.etree.ElementTree as ET

import pytest
from obsw.pus.services.s02_device_access import REGISTERS
from obsw_host.sample import SDB_PATH
from obsw_host.yamcs import database
from obsw_host.yamcs.xtce import generate
from test_yamcs_config import NS, commands, containers


@pytest.fixture(scope="module")
def root():
    return ET.fromstring(generate(database.load(SDB_PATH)))


def _entries(cmd):
    out = []
    for e in cmd.find("x:CommandContainer/x:EntryList", NS):
        out.append((e.get("name") or e.get("argumentRef"), e.get("sizeInBits")))
    return out


def _service(cmd):
    a = cmd.findall("x:BaseMetaCommand/x:ArgumentAssignmentList/x:ArgumentAssignment", NS)
    return tuple(int(x.get("argumentValue")) for x in a)


def test_commands_of_the_new_types(root):
    cmds = commands(root)
    expected = {
        "time_rate": (9, 1),
        "device_on_off": (2, 1),
        "device_register_load": (2, 2),
        "device_cpdu": (2, 4),
        "device_register_dump": (2, 5),
        "diag_enable": (3, 7),
        "diag_disable": (3, 8),
        "diag_structures": (3, 11),
        "diag_delete": (3, 4),
        "diag_one_shot": (3, 28),
        "diag_interval": (3, 32),
        "diag_properties": (3, 34),
        "hk_append": (3, 29),
        "diag_append": (3, 30),
        "functional_apply": (3, 37),
        "functional_delete": (3, 39),
        "functional_report": (3, 40),
        "forward_diag_add": (14, 9),
        "forward_diag_delete": (14, 10),
        "forward_diag_report": (14, 11),
    }
    for name, msg_type in expected.items():
        assert _service(cmds["/obsw-demo/PUS/" + name]) == msg_type, name


def test_register_load_is_laid_out_as_the_user_packs_it(root):
    cmd = commands(root)["/obsw-demo/PUS/device_register_load"]
    assert _entries(cmd) == [("n", "8"), ("address", None), ("value", None)]
    one = REGISTERS.pack({"items": [{"address": 0x000A0001, "value": 5}]})
    assert len(one) == 1 + 4 + 4
    sizes = {
        t.get("name"): int(t.find("x:IntegerDataEncoding", NS).get("sizeInBits"))
        for t in root.iter("{%s}IntegerArgumentType" % NS["x"])
    }
    assert sizes["device_register_load_address_t"] == sizes["device_register_load_value_t"] == 32


def test_report_containers(root):
    found = containers(root)
    for name in (
        "cuc_time_report",
        "cds_time_report",
        "diag_report",
        "register_dump",
        "diag_structure_report",
        "diag_properties_report",
        "functional_reporting_report",
        "forward_diag_report",
    ):
        assert name in found, name
