"""tools/bench/smoke.py: what it takes for a benchmark's figures, and what it refuses."""

import importlib.util
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
# loaded by its file: tools/bench on sys.path would shadow the peers (its spacecan.py)
_spec = importlib.util.spec_from_file_location(
    "bench_smoke", ROOT / "tools" / "bench" / "smoke.py"
)
smoke = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(smoke)

ROW = {"case": "c", "impl": "obsw", "value": 1.5, "unit": "u", "higher_is_better": True}


def test_a_result_in_the_common_format_has_no_problems():
    assert smoke.problems({"bench": "x", "rows": [ROW, dict(ROW, impl="peer")]}, "x") == []


def test_no_rows_is_a_problem():
    assert smoke.problems({"bench": "x", "rows": []}, "x") == ["no rows"]


def test_a_value_that_is_no_finite_number_is_a_problem():
    for bad in (None, "1", float("nan"), float("inf"), True):
        out = smoke.problems({"bench": "x", "rows": [dict(ROW, value=bad)]}, "x")
        assert len(out) == 1 and "not a finite number" in out[0], bad


def test_a_row_without_a_field_and_rows_without_obsw_are_problems():
    row = dict(ROW)
    del row["unit"]
    assert smoke.problems({"bench": "x", "rows": [row]}, "x") == ["row 0 has no unit"]
    assert smoke.problems({"bench": "x", "rows": [dict(ROW, impl="peer")]}, "x") == [
        "no row of obsw's"
    ]


def test_every_script_is_a_listed_benchmark_or_a_helper():
    assert smoke.unlisted() == []


def test_a_benchmark_that_breaks_fails_the_run(tmp_path, monkeypatch):
    broken = tmp_path / "broken.py"
    broken.write_text("raise SystemExit('no mission named')\n")
    monkeypatch.setattr(smoke, "HERE", tmp_path)
    monkeypatch.setitem(smoke.report.RUNS, "broken", ("broken.py", {}, "broken"))
    outcome, _, detail = smoke.smoke("broken", 60)
    assert outcome == "failed" and "no mission named" in detail


def test_a_benchmark_that_cannot_run_here_is_a_skip_with_its_reason(tmp_path, monkeypatch):
    script = tmp_path / "away.py"
    script.write_text("import sys\nprint('Yamcs needs Java', file=sys.stderr)\nsys.exit(77)\n")
    monkeypatch.setattr(smoke, "HERE", tmp_path)
    monkeypatch.setitem(smoke.report.RUNS, "away", ("away.py", {}, "away"))
    assert smoke.smoke("away", 60)[::2] == ("skipped", "Yamcs needs Java")


def test_the_last_line_counts_passed_failed_skipped():
    res = subprocess.run(
        [sys.executable, str(ROOT / "tools" / "bench" / "smoke.py"), "pluto"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert res.returncode == 0, res.stdout + res.stderr
    assert res.stdout.strip().splitlines()[-1] == "1 passed, 0 failed, 0 skipped"
