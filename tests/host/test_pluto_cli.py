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


def check_args(tmp_path, text, **options):
    f = tmp_path / "p.plt"
    f.write_text(text)
    ns = argparse.Namespace(file=str(f), sdb=None, system=None, mission=None, syntax_only=False)
    for k, v in options.items():
        setattr(ns, k, v)
    return cmd.check_cmd(ns)


def test_check_against_a_mission(tmp_path, capsys):
    text = ("procedure initiate and confirm step Check main wait until coil_temp of Magnetorquer"
            " < 1800 timeout 5 s; initiate and confirm enable of Magnetorquer; end main end step;"
            " end procedure")  # fmt: skip
    assert check_args(tmp_path, text, mission="examples/aurora") == 1
    out = capsys.readouterr().out
    assert ("p.plt:1:85: type_error: cannot compare coil_temp of Magnetorquer (degC) with 1800:"
            " units degC and none differ") in out  # fmt: skip
    assert check_args(tmp_path, text.replace("1800", "80 degC"), mission="examples/aurora") == 0
    assert check_args(tmp_path, text.replace("enable", "enabel"), mission="examples/aurora") == 1
    assert "unknown activity enabel of Magnetorquer" in capsys.readouterr().out


def test_check_syntax_only(tmp_path, capsys):
    # references nothing resolves still pass: the grammar alone is checked
    assert check_args(tmp_path, "procedure initiate and confirm fly of Nowhere; end procedure",
                      syntax_only=True) == 0  # fmt: skip
    assert "ok (syntax)" in capsys.readouterr().out
    assert check_args(tmp_path, "procedure\n  log 1 +;\nend procedure", syntax_only=True) == 1
    assert capsys.readouterr().out.endswith(
        "p.plt:2:10: syntax_error: expected an expression, found ';'\n"
    )


def test_check_takes_one_source_of_references(tmp_path):
    with pytest.raises(UserError) as e:
        check_args(tmp_path, "procedure log 1; end procedure", mission="m", syntax_only=True)
    assert "--mission and --syntax-only" in str(e.value)


def test_a_mission_that_does_not_load_is_named(tmp_path):
    with pytest.raises(UserError) as e:
        check_args(tmp_path, "procedure log 1; end procedure", mission=str(tmp_path))
    assert str(tmp_path) in str(e.value)
