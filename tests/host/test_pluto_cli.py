"""`obsw pluto check` and `obsw pluto run`: activity signatures from the database, system files
with values with units, and system files it cannot play named with the file."""

import argparse
import json

import pytest
from obsw_host.commands import pluto as cmd
from obsw_host.errors import UserError

DATA = "tests/data/pluto/"
CPDU = {
    "name": "CpduN",
    "operations": [
        {
            "name": "set_state_bits",
            "arguments": [{"name": "state", "type": "uint8"}, {"name": "mask", "type": "uint8"}],
        }
    ],
}


def check(tmp_path, text, sdb=None, system=None):
    f = tmp_path / "p.pluto"
    f.write_text(text)
    ns = argparse.Namespace(file=str(f), sdb=None, system=None)
    if sdb is not None:
        ns.sdb = str(tmp_path / "sdb.json")
        (tmp_path / "sdb.json").write_text(json.dumps(sdb))
    if system is not None:
        ns.system = str(tmp_path / "system.json")
        (tmp_path / "system.json").write_text(json.dumps(system))
    return cmd.check_cmd(ns)


def test_check_with_sdb_signature(tmp_path, capsys):
    ok = "procedure initiate and confirm set_state_bits of CpduN with arguments 5, 255 end with;"
    assert check(tmp_path, ok + " end procedure", {"components": [CPDU]}) == 0
    bad = (
        "procedure initiate and confirm set_state_bits of CpduN with arguments state := 5,"
        " gain := 2 end with; end procedure"
    )
    assert check(tmp_path, bad, {"components": [CPDU]}) == 1
    out = capsys.readouterr().out
    assert "unknown_reference: activity set_state_bits of CpduN has no argument gain" in out
    assert "type_error: activity set_state_bits of CpduN needs argument mask" in out


def test_sdb_resolver_signature():
    r = cmd.SdbResolver({"components": [CPDU]})
    assert r.signature("set_state_bits of CpduN") == [("state", "u", None), ("mask", "u", None)]
    assert r.signature("reset of CpduN") is None


def test_system_file_it_cannot_play_names_the_file(tmp_path):
    spec = {"parameters": {"v of EPS": {"timeline": [[0, {"value": 1, "unit": "V"}], [1, 2]]}},
            "activities": {"a of B": {"duration_s": {"value": 1, "unit": "V"}}}}  # fmt: skip
    with pytest.raises(UserError) as e:
        check(tmp_path, "procedure log 1; end procedure", system=spec)
    assert str(e.value).endswith("system.json: activity a of B, duration_s: 1 V is not a"
                                 " relative time")  # fmt: skip
    (tmp_path / "p.pluto").write_text("procedure log 1; end procedure")
    ns = argparse.Namespace(file=str(tmp_path / "p.pluto"), system=str(tmp_path / "system.json"),
                            arg=[], quiet=True)  # fmt: skip
    with pytest.raises(UserError):
        cmd.run_cmd(ns)


def test_run_the_procedure_written_from_the_grammar(capsys):
    ns = argparse.Namespace(file=DATA + "annex_a.pluto", system=DATA + "annex_a.system.json",
                            arg=[], quiet=True)  # fmt: skip
    assert cmd.run_cmd(ns) == 0
    trace = json.loads(capsys.readouterr().out)
    assert trace["status"] == "confirmed"
    assert trace["user_messages"][0] == "battery at 7.2 V"


def test_run_argument_with_units(tmp_path, capsys):
    f = tmp_path / "p.pluto"
    f.write_text("procedure main log limit, limit > 2 V; end main end procedure")
    ns = argparse.Namespace(file=str(f), system=None, quiet=True,
                            arg=['limit={"value": 2500, "unit": "mV"}'])  # fmt: skip
    assert cmd.run_cmd(ns) == 0
    assert json.loads(capsys.readouterr().out)["log"] == ["2500 mVTRUE"]
    ns.arg = ['limit={"value": 1, "unit": "parsec"}']
    with pytest.raises(UserError):
        cmd.run_cmd(ns)
