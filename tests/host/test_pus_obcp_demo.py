"""Service 18 on the host: the OBCP demo end to end over loopback UDP, the packaged spacecraft
database's OBCP events, and the `obsw obcp` command's value parsing."""

import argparse
import json

import obcp_demo
from obsw.pluto.obcp import ENGINE
from obsw.pus.services.s18_layouts import sdb_events
from obsw_host.commands import obcp as obcp_command
from obsw_host.pus.obcp_onboard import onboard_with_obcp
from obsw_host.sample import SDB_PATH


def test_demo_uploads_runs_and_reports():
    lines = []
    assert obcp_demo.run(out=lines.append) == 0
    text = "\n".join(lines)
    assert "syntax error at line 4, column 3" in text
    assert "event turn_panel step Deploy executing" in text
    assert "event turn_panel log: angle before: 0.0 deg" in text
    assert "event turn_panel log: angle after: 30.0 deg" in text
    assert "event turn_panel finished confirmed" in text
    assert "turn_panel  inactive  last outcome confirmed" in text
    assert lines[-1] == "OBCP demo done"


def test_packaged_database_lists_the_engine_events():
    with open(SDB_PATH) as f:
        doc = json.load(f)
    listed = {e["name"]: e for e in doc["events"] if e["name"].startswith("obcp.")}
    assert listed == {e["name"]: e for e in sdb_events(ENGINE)}


def test_command_values_and_parsers():
    assert obcp_command.parse_value("30 deg") == {"value": 30.0, "unit": "deg"}
    assert obcp_command.parse_value("true") is True
    assert obcp_command.parse_value("north") == "north"
    assert obcp_command.parse_arguments(["n=3", "a=1.5 V"]) == {
        "n": 3,
        "a": {"value": 1.5, "unit": "V"},
    }
    p = argparse.ArgumentParser()
    obcp_command.add_parser(p.add_subparsers(dest="command"))
    args = p.parse_args(["obcp", "--port", "1", "activate", "x", "--arg", "n=2", "--level", "3"])
    assert (args.name, args.arg, args.level, args.port) == ("x", ["n=2"], 3, 1)
    g = argparse.ArgumentParser()
    obcp_command.add_client_options(g)
    obcp_command.add_to_ground(g.add_subparsers(dest="action"))
    args = g.parse_args(["obcp", "stop-unload", "x"])
    assert args.func is obcp_command._simple and args.action_name == "stop-unload"


TWO_STEPS = """procedure
  main
    initiate and confirm step First main log "first"; end main end step;
    initiate and confirm step Second main log "second"; end main end step;
  end main
end procedure
"""


def test_step_commands_run_a_procedure_one_step_at_a_time(tmp_path, capsys):
    from obsw.pus import sdb as sdb_module

    sdb = sdb_module.load(SDB_PATH)
    onboard, engine = onboard_with_obcp(sdb, port=0, period=0.05)
    path = tmp_path / "two.plt"
    path.write_text(TWO_STEPS)
    p = argparse.ArgumentParser()
    obcp_command.add_parser(p.add_subparsers(dest="command"))
    onboard.start()
    try:
        port = str(onboard.address[1])

        def cli(*words):
            args = p.parse_args(["obcp", "--port", port, "--json", *words])
            code = args.func(args)
            return code, json.loads(capsys.readouterr().out.strip().splitlines()[-1])

        def status_until(state):
            for _ in range(200):  # each one a TC[18,8] round trip
                code, out = cli("status")
                obcps = {o["id"]: o for o in out["replies"][0]["obcps"]}
                if obcps["two"]["status"] == state:
                    return obcps["two"]
            return obcps["two"]

        assert cli("load", "two", str(path))[0] == 0
        code, out = cli("step-activate", "two", "--level", "3")
        assert code == 0 and out["explained"][-1] == "completion success"
        assert status_until("suspended")["status"] == "suspended"
        assert onboard.call(lambda: engine.status("two")["steps"]) == {"First": "confirmed"}
        code, out = cli("step", "two")
        assert code == 0
        st = status_until("inactive")
        assert (st["status"], st["outcome"]) == ("inactive", "confirmed")
        code, out = cli("step", "two")  # no longer suspended
        assert code == 1 and "NOT_SUSPENDED" in " ".join(out["explained"])
    finally:
        onboard.stop()
        engine.system.close()
