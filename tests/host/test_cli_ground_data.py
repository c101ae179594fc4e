"""Statistics (service 4), packet stores and their downlink (service 15) and files (service 23)
from the real `obsw ground`, against `obsw obc serve`; replies by name, in tables, UTC times."""

import json

from test_cli_ground import obc, obsw  # noqa: F401


def ground(port, *args):
    return obsw("ground", "--port", port, *args)


def ok(port, *args):
    r = ground(port, *args)
    assert r.returncode == 0, r.stdout + r.stderr
    return [x for x in r.stdout.splitlines() if not x.startswith("  ")]  # no stages


def test_statistics_by_parameter_with_units_and_utc(obc):  # noqa: F811 (the fixture)
    port, _ = obc
    ok(port, "stats", "add", "SolarPanel.speed:1")
    ground(port, "hk", "report", 1)  # some cycles pass
    lines = ok(port, "stats", "report")
    assert lines[0].startswith("from 20") and lines[0].endswith("Z")
    assert lines[1].split()[:3] == ["parameter", "samples", "max"]
    row = lines[2].split()
    assert row[0] == "SolarPanel.speed" and row[3] == "deg/s" and row[4].endswith("Z")
    out = json.loads(ground(port, "--json", "stats", "report", "--reset").stdout)
    assert out["request"] == "TC[4,1]" and "SolarPanel.speed" in out["replies"][0]["statistics"]


def test_packet_store_created_filled_and_downlinked(obc):  # noqa: F811
    port, _ = obc
    ok(port, "store", "create", 1, 65536)
    ok(port, "store", "add-types", 1, "10:17:2")
    ok(port, "store", "enable", 1)
    ok(port, "ping")
    ok(port, "ping")
    summary = ok(port, "store", "summary", 1)
    assert summary[0].split()[:3] == ["store", "oldest", "newest"]
    row = dict(zip(summary[0].split(), summary[1].split()))
    assert int(row["count"]) >= 2 and row["oldest"].endswith("Z"), summary
    ok(port, "store", "downlink", 1, "--from", "2020-01-01T00:00:00Z", "--to", row["newest"])
    ok(port, "store", "downlink", 1, "--first", row["first_seq"], "--last", row["last_seq"])
    status = ok(port, "store", "status")
    assert status[1].split()[:2] == ["1", "yes"]
    bad = ground(port, "store", "downlink", 1, "--from", "2020-01-01T00:00:00Z")
    assert bad.returncode == 2 and "--from UTC --to UTC" in bad.stderr
    bad = ground(port, "store", "delete-before", "yesterday")
    assert bad.returncode == 2 and "expected UTC" in bad.stderr


def test_files_created_copied_found_and_deleted(obc):  # noqa: F811
    port, _ = obc
    ok(port, "file", "mkdir", "SAT:/ops")
    ok(port, "file", "create", "SAT:/ops/a.txt", "--max-size", 1000)
    ok(port, "file", "copy", "SAT:/ops/a.txt", "SAT:/ops/b.txt")
    assert "max_size: 1000" in ok(port, "file", "attributes", "SAT:/ops/a.txt")
    found = ok(port, "file", "find", "SAT:/ops", "*.txt")
    assert found == ["SAT:/ops/a.txt", "SAT:/ops/b.txt"], found
    listing = ok(port, "list", "files", "SAT:/ops")
    assert listing[0] == "SAT:/ops" and ["b.txt", "file"] in [x.split() for x in listing]
    ok(port, "file", "delete", "SAT:/ops/b.txt")
    assert ok(port, "file", "find", "SAT:/ops", "*.txt") == ["SAT:/ops/a.txt"]
    r = ground(port, "file", "delete", "SAT:/ops/none.txt")
    assert r.returncode == 1 and "failure" in r.stdout


def test_tc_by_name_checked_against_types_and_ranges_before_sending(obc):  # noqa: F811
    port, log = obc
    ok(port, "tc", "SolarPanel.deploy")
    ok(port, "tc", "SolarPanel.set_angle", "angle=15")
    ok(port, "tc", "SolarPanel.speed=7.5")
    assert ok(port, "params", "get", "SolarPanel.speed") == ["SolarPanel.speed = 7.5 deg/s"]
    for args, says in (
        (("SolarPanel.set_angle", "angle=1e40"), "float32"),  # the type cannot carry it
        (("SolarPanel.set_angle", "angel=3"), "no argument 'angel'; expected angle"),
        (("SolarPanel.set_angle",), "needs angle"),
        (("SolarPanel.speed=25",), "outside the database's range; expected 0.1 to 20"),
        (("SolarPanel.angle=3",), "read-only"),
        (("Nope.x",), "expected one of `obsw ground list functions`"),
        (("17",), "expected SERVICE SUBTYPE [HEX]"),
    ):
        r = ground(port, "-v", "tc", *args)
        assert r.returncode == 2 and says in r.stderr, (args, r.stderr)
        assert "TC ->" not in r.stderr  # nothing was sent
    assert ok(port, "params", "get", "SolarPanel.speed") == ["SolarPanel.speed = 7.5 deg/s"]


def test_a_tc_sent_in_large_packet_parts_is_verified_as_itself(obc):  # noqa: F811
    port, _ = obc
    r = ground(port, "-v", "--json", "large", 17, 1, "--part-size", 4)
    out = json.loads(r.stdout.splitlines()[-1])
    assert r.returncode == 0 and out["request"] == "TC[17,1]", r.stdout
    assert out["verification"][-1] == "completion success"
    assert "TC[13,9]" in r.stderr and "TC[13,11]" in r.stderr  # it went in parts
    out = json.loads(ground(port, "--json", "large", 3, 99).stdout)
    assert out["request"] == "TC[3,99]" and out["failure"]["code"] == 4  # illegal subtype
