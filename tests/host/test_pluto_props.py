"""PLUTO properties: expressions evaluate like Python's arithmetic, random text only ever
raises the declared syntax error, and the dry-run command's trace and check output."""

import argparse
import json

from hypothesis import assume, given, settings
from hypothesis import strategies as st
from obsw.pluto.evaluate import Evaluator
from obsw.pluto.exprs import ExprParser
from obsw.pluto.lexer import PlutoError, PlutoSyntaxError, tokenize
from obsw.pluto.parser import parse
from obsw_host.commands import pluto as cmd


def evaluate(text):
    p = ExprParser(tokenize(text))
    e = p.expr()
    assert p.tok()[0] == "e", "trailing tokens in %r" % text
    return Evaluator(None, {}, {}).eval(e)


ints = st.integers(min_value=-50, max_value=50).map(str)


def arith(children):
    return st.one_of(
        st.tuples(children, st.sampled_from(["+", "-", "*", "/"]), children).map(
            lambda t: "%s %s %s" % t
        ),
        children.map(lambda c: "(%s)" % c),
    )


ARITH = st.recursive(ints, arith, max_leaves=12)


@settings(max_examples=200, deadline=None)
@given(ARITH)
def test_arithmetic_matches_python(text):
    try:
        expected = eval(text)  # the oracle: Python's precedence and left associativity
    except ZeroDivisionError:
        assume(False)
    assume(abs(expected) < 1e12)
    got = evaluate(text)
    assert abs(got - expected) <= 1e-9 * max(1.0, abs(expected)), (text, got, expected)


def logic(children):
    return st.one_of(
        st.tuples(children, st.sampled_from(["AND", "OR"]), children).map(
            lambda t: "%s %s %s" % t
        ),
        children.map(lambda c: "(%s)" % c),
        children.map(lambda c: "NOT (%s)" % c),
    )


ATOMS = st.one_of(
    st.sampled_from(["TRUE", "FALSE"]),
    st.tuples(ints, st.sampled_from(["<", ">", "<=", ">=", "=", "!="]), ints).map(
        lambda t: "%s %s %s" % t
    ),
)
LOGIC = st.recursive(ATOMS, logic, max_leaves=10)


def to_python(text):
    for a, b in (("AND", "and"), ("OR", "or"), ("NOT", "not"), ("TRUE", "True"),
                 ("FALSE", "False"), ("!=", "<>"), ("<=", "@le"), (">=", "@ge"), ("=", "=="),
                 ("<>", "!="), ("@le", "<="), ("@ge", ">=")):  # fmt: skip
        text = text.replace(a, b)
    return text


@settings(max_examples=200, deadline=None)
@given(LOGIC)
def test_boolean_precedence_matches_python(text):
    assert bool(evaluate(text)) == eval(to_python(text)), text


@settings(max_examples=200, deadline=None)
@given(st.lists(st.integers(min_value=-9, max_value=9), min_size=2, max_size=6))
def test_subtraction_and_division_are_left_associative(xs):
    assume(all(x != 0 for x in xs[1:]))
    for op in ("-", "/"):
        text = (" %s " % op).join(str(x) for x in xs)
        assert abs(evaluate(text) - eval(text)) < 1e-9


WORDS = ["procedure", "end", "main", "step", "initiate", "and", "confirm", "if", "then",
         "else", "log", "x", ":=", "1", "2.5 V", ";", "(", ")", "in", "case", "is", "wait",
         "for", "until", "s", "declare", "variable", "of", "type", "real", '"t"', "+", "*",
         "timeout", "raise", "event", "while", "do", "parallel", "0x1F", ","]  # fmt: skip


@settings(max_examples=200, deadline=None)
@given(
    st.one_of(st.text(max_size=80), st.lists(st.sampled_from(WORDS), max_size=30).map(" ".join))
)
def test_random_text_raises_only_syntax_errors(text):
    try:
        parse(text)
    except PlutoSyntaxError as e:
        assert e.line >= 1 and e.col >= 1


def test_check_command_reports_line_and_column(tmp_path, capsys):
    f = tmp_path / "bad.pluto"
    f.write_text(
        "procedure\n  initiate and confirm step S main\n    x := 1;\n"
        "  end main end step;\nend procedure\n"
    )
    rc = cmd.check_cmd(argparse.Namespace(file=str(f), sdb=None, system=None))
    out = capsys.readouterr().out
    assert rc == 1
    assert out.strip() == "%s:3:5: unknown_reference: unknown reference x" % f


def test_check_command_with_sdb(tmp_path, capsys):
    f = tmp_path / "p.pluto"
    f.write_text("procedure initiate and confirm set_state_bits of CpduN; end procedure")
    sdb = tmp_path / "sdb.json"
    cpdu = {"name": "CpduN", "operations": [{"name": "set_state_bits"}]}
    sdb.write_text(json.dumps({"components": [cpdu]}))
    assert cmd.check_cmd(argparse.Namespace(file=str(f), sdb=str(sdb), system=None)) == 0
    cpdu["operations"] = [{"name": "reset"}]
    sdb.write_text(json.dumps({"components": [cpdu]}))
    assert cmd.check_cmd(argparse.Namespace(file=str(f), sdb=str(sdb), system=None)) == 1
    assert "unknown activity set_state_bits of CpduN" in capsys.readouterr().out


def test_dry_run_trace_of_sample():
    with open("tests/data/pluto/deploy_and_track.pluto") as f:
        src = f.read()
    with open("tests/data/pluto/deploy_and_track.system.json") as f:
        spec = json.load(f)
    seen = []
    trace = cmd.dry_run(src, spec, on_statement=lambda t, line, what: seen.append((t, line, what)))
    assert trace["accept"] and trace["error"] is None
    assert trace["status"] == "confirmed"
    assert trace["end_time_s"] == 63
    assert trace["step_status"] == {"Deploy": "confirmed"}
    assert [c["activity"] for c in trace["activity_calls"]] == [
        "set_state_bits of CpduN", "set_state_bits of CpduN",
        "Switch on Star Tracker1", "Switch on Star Tracker2",
    ]  # fmt: skip
    assert trace["activity_calls"][0]["arguments"] == {"state": 5, "mask": 255}
    assert trace["parameter_reads"][0] == "angle of SolarPanel"
    assert trace["user_messages"][-1] == "done at 2025-01-01T00:01:03.000Z"
    assert (0 + 5, 12, "initiate and confirm step Deploy") in seen
    json.dumps(trace)


def test_dry_run_reports_rejections():
    trace = cmd.dry_run("procedure log 1 +; end procedure")
    assert trace["accept"] is False
    assert trace["error"] == {
        "kind": "syntax_error",
        "line": 1,
        "message": trace["error"]["message"],
    }
    trace = cmd.dry_run("procedure log tilt of X; end procedure", {"parameters": {"a of B": 1}})
    assert trace["error"]["kind"] == "unknown_reference"
    trace = cmd.dry_run("procedure log 1 + TRUE; end procedure")
    assert trace["error"]["kind"] == "type_error"
    assert trace["status"] is None


def test_load_errors_are_one_family():
    for src in ("procedure log 1 +; end procedure", "procedure log y; end procedure"):
        try:
            parse(src) if "+" in src else cmd.load(src)
        except PlutoError as e:
            assert e.kind in ("syntax_error", "unknown_reference", "type_error")
        else:
            raise AssertionError("accepted " + src)


def test_sdb_resolver_reads_the_spacecraft_database_layout():
    r = cmd.SdbResolver(
        {
            "components": [
                {
                    "name": "SolarPanel",
                    "attributes": [
                        {"name": "angle", "parameter": 1, "type": "float32", "unit": "deg"}
                    ],
                    "events": [{"name": "angle_reached", "id": 1}],
                }
            ]
        }  # fmt: skip
    )
    assert r.describe("angle of SolarPanel") == ("parameter", "r", "deg")
    assert r.describe("angle_reached of SolarPanel") == ("event", "?", None)
    assert r.describe("tilt of SolarPanel") is None
