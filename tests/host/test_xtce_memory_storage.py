"""XTCE entries of services 6, 15 (copy, diagnostic storage), 21 (by reference) and 22
(orbit): every new request has its command, laid out as the service user packs it."""

import xml.etree.ElementTree as ET

import pytest
from obsw.pus.services import s06_layouts as lay06
from obsw.pus.services.s15_layouts import COPY_WINDOW
from obsw_host.sample import SDB_PATH
from obsw_host.yamcs import database
from obsw_host.yamcs.xtce import generate

NS = {"x": "http://www.omg.org/spec/XTCE/20180204"}


@pytest.fixture(scope="module")
def pus_commands():
    root = ET.fromstring(generate(database.load(SDB_PATH)))
    pus = root.find("x:SpaceSystem[@name='PUS']", NS)
    return {c.get("name"): c for c in pus.iter("{%s}MetaCommand" % NS["x"])}


def layout(cmd):
    """(service, subtype) and the names of the entries after the PUS header."""
    assigns = {
        a.get("argumentName"): int(a.get("argumentValue"))
        for a in cmd.iter("{%s}ArgumentAssignment" % NS["x"])
    }
    entries = cmd.find("x:CommandContainer/x:EntryList", NS)
    names = [e.get("name") or e.get("argumentRef") for e in entries]
    return (assigns["service"], assigns["subtype"]), names


EXPECTED = {
    "memory_abort_dumps": ((6, 12), []),
    "memory_scrub_enable": ((6, 13), ["memory"]),
    "memory_scrub_disable": ((6, 14), ["memory"]),
    "memory_protect": ((6, 15), ["memory"]),
    "memory_unprotect": ((6, 16), ["memory"]),
    "memory_dump": ((6, 5), ["memory", "n", "address", "length"]),
    "memory_check": ((6, 9), ["memory", "n", "address", "length"]),
    "memory_dump_object": ((6, 3), ["memory", "object", "n", "offset", "length"]),
    "memory_check_object": ((6, 7), ["memory", "object", "n", "offset", "length"]),
    "memory_check_whole_object": ((6, 17), ["memory", "object"]),
    "memory_load_file": ((6, 19), ["memory", "n", "address", "repository", "file", "crc"]),
    "memory_dump_file": ((6, 20), ["memory", "n", "address", "length", "repository", "file"]),
    "memory_load_object_file": (
        (6, 21),
        ["memory", "object", "n", "offset", "repository", "file", "crc"],
    ),
    "memory_dump_object_file": (
        (6, 22),
        ["memory", "object", "n", "offset", "length", "repository", "file"],
    ),
    "store_copy": (
        (15, 24),
        [
            "window",
            "tag1_seconds",
            "tag1_fraction",
            "tag2_seconds",
            "tag2_fraction",
            "source",
            "target",
        ],
    ),
    "store_diag_add": ((15, 31), ["store", "n", "apid", "sid_count", "sid"]),
    "store_diag_delete": ((15, 32), ["store", "n", "apid", "sid_count", "sid"]),
    "store_diag_report": ((15, 37), ["store"]),
    "sequence_load_file": ((21, 2), ["sequence", "repository", "file"]),
    "sequence_load_file_activate": ((21, 8), ["sequence", "repository", "file"]),
    "position_set_orbit": ((22, 28), ["orbit"]),
}


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_each_new_request_has_its_command(pus_commands, name):
    assert layout(pus_commands[name]) == EXPECTED[name]


def flat(structure):
    """The field names of a core layout, a repeated group as its count "n" and one item."""
    out = []
    for name, f in structure.fields:
        item = getattr(f, "item", None)
        if item is None:
            out.append(name)
        else:
            out.append("n")
            out += [x for x, _ in item.fields]
    return out


@pytest.mark.parametrize(
    "name, layout",
    [
        ("memory_dump", lay06.RANGES),
        ("memory_dump_object", lay06.OBJECT_RANGES),
        ("memory_check_whole_object", lay06.ONE_OBJECT),
        ("memory_load_file", lay06.LOAD_BY_REFERENCE),
        ("memory_dump_file", lay06.DUMP_TO_FILE),
        ("memory_load_object_file", lay06.OBJECT_LOAD_BY_REFERENCE),
        ("memory_dump_object_file", lay06.OBJECT_DUMP_TO_FILE),
        ("memory_protect", lay06.ONE_MEMORY),
    ],
)
def test_commands_follow_the_core_layouts(name, layout):
    expected = [("crc" if n == "checksum" else n) for n in flat(layout)]
    assert EXPECTED[name][1] == expected


def test_store_copy_follows_the_core_layout():
    names = [n for n, _ in COPY_WINDOW.fields]
    assert names == ["window", "tag1", "tag2", "source", "target"]
    xtce = [n.split("_")[0] for n in EXPECTED["store_copy"][1]]
    assert [n for i, n in enumerate(xtce) if n not in xtce[:i]] == names
