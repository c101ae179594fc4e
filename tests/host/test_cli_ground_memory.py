"""`obsw ground memory|store|sequence|position` against a running `obsw obc serve`: services 6,
15 (copy, diagnostic storage), 21 (by reference) and 22 (orbit) through the operator's CLI."""

import json

from obsw.crc import crc16_ccitt
from test_cli_ground import obc, obsw  # noqa: F401 (obc is a fixture)

IMAGE = 0x08000000  # the sample database's memory 1


def ground(port, *args):
    r = obsw("ground", "--port", port, "--json", *args)
    return r.returncode, json.loads(r.stdout.splitlines()[-1]) if r.stdout else r.stderr


def test_memory_load_dump_protect_and_files(obc, tmp_path):  # noqa: F811
    port, _ = obc
    files = tmp_path / "state" / "files"
    code, out = ground(port, "memory", "load", 1, hex(IMAGE + 16), "cafe01")
    assert code == 0, out
    code, out = ground(port, "memory", "dump", 1, hex(IMAGE + 16), 3)
    assert code == 0 and out["replies"][0]["items"][0]["data"] == "cafe01"
    code, out = ground(port, "memory", "dump", 1, 16, 3, "--object", 0)  # object memory
    assert out["replies"][0]["items"][0] == {
        "offset": 16,
        "data": "cafe01",
        "checksum": crc16_ccitt(b"\xca\xfe\x01"),
        "ok": True,
    }
    code, out = ground(port, "memory", "check-object", 1, 0)
    assert out["replies"][0]["length"] == 65536
    # write protection holds for every load
    assert ground(port, "memory", "protect", 1, "on")[0] == 0
    code, out = ground(port, "memory", "load", 1, hex(IMAGE), "00", "--atomic")
    assert code == 1 and out["failure"]["code"] == 33
    assert ground(port, "memory", "protect", 1, "off")[0] == 0
    # a dump into a file of the on-board filestore, and a load from it
    code, out = ground(port, "memory", "dump", 1, hex(IMAGE), 8192, "--to", "SAT:/dump.bin")
    assert code == 0, out
    dumped = (files / "dump.bin").read_bytes()
    assert len(dumped) == 8192 and dumped[16:19] == b"\xca\xfe\x01"
    local = tmp_path / "dump.bin"
    local.write_bytes(dumped[16:19])
    (files / "patch.bin").write_bytes(dumped[16:19])  # as if uploaded by CFDP
    code, out = ground(
        port, "memory", "load-file", 1, hex(IMAGE + 100), "SAT:/patch.bin", "--local", local
    )
    assert code == 0, out
    code, out = ground(port, "memory", "dump", 1, hex(IMAGE + 100), 3)
    assert out["replies"][0]["items"][0]["data"] == "cafe01"
    assert ground(port, "memory", "scrub", 1, "on")[0] == 0
    assert ground(port, "memory", "abort-dumps")[0] == 0


def test_store_sequence_and_orbit(obc, tmp_path):  # noqa: F811
    port, _ = obc
    files = tmp_path / "state" / "files"
    code, out = ground(port, "store", "copy", 1, 2, "--from", 0)
    assert code == 1 and out["failure"]["code"] == 9  # no packet store 1 yet
    code, out = ground(port, "store", "diag", "list", 1)
    assert code == 1 and out["failure"]["code"] == 9
    seq = tmp_path / "warmup.seq"
    r = obsw("ground", "--port", port, "sequence", "file", seq, "0 ping", "1 ping")
    assert r.returncode == 0, r.stderr
    (files / "warmup.seq").write_bytes(seq.read_bytes())  # as if uploaded by CFDP
    code, out = ground(port, "sequence", "load-file", "warmup", "SAT:/warmup.seq", "--activate")
    assert code == 0, out
    code, out = ground(port, "sequence", "content", "warmup")
    assert [i["delay"] for i in out["replies"][0]["items"]] == [0.0, 1.0]
    code, out = ground(port, "position", "orbit", 1234)
    assert code == 0, out
    code, out = ground(port, "params", "get", "nav.distance")
    assert out["replies"][0]["values"]["nav.distance"] == 1234


def test_bad_input_is_named_without_a_traceback():
    for args, text in (
        (("memory", "load", 1, "zz", "00"), "'zz': expected an integer"),
        (("memory", "load", 1, 0, "xyz"), "'xyz': expected hexadecimal octets"),
        (("store", "copy", 1, 2, "--from", "yesterday"), "'yesterday': expected YYYY-MM-DD"),
        (("store", "copy", 1, 2), "without a time window"),
        (("memory", "load-file", 1, 0, "SAT:/x.bin"), "one of the arguments --local"),
    ):
        r = obsw("ground", *args)
        assert r.returncode in (1, 2) and text in r.stderr, (args, r.stderr)
        assert "Traceback" not in r.stderr
