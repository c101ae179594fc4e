"""The documentation keeps to its rules: the README is a short front page whose links resolve,
benchmark pages say what their saved data says, and the conventions page lists the modules
the imports check allows."""

import importlib.util
import json
import pathlib
import re
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))

import check_imports  # noqa: E402
from obsw_host.mission.config import MissionConfig  # noqa: E402


def _load(name, path):
    """A tool module by its file: tools/bench on sys.path would shadow peers (spacecan.py)."""
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


report = _load("bench_report", ROOT / "tools" / "bench" / "report.py")

README_MAX = 15_000  # bytes: a front page, the rest lives in docs/


def _links(path):
    text = path.read_text()
    return [m for m in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", text) if "://" not in m]


def test_the_readme_is_a_short_front_page():
    readme = ROOT / "README.md"
    assert len(readme.read_bytes()) < README_MAX
    text = readme.read_text()
    for must in ("tools/demo", "tools/test", "tools/bootstrap", '.venv/bin:$PATH"'):
        assert must in text


def test_the_readmes_links_resolve():
    links = _links(ROOT / "README.md")
    assert len(links) >= 15
    missing = [link for link in links if not (ROOT / link).exists()]
    assert missing == []


def test_the_benchmark_pages_match_their_saved_data():
    assert report.stale() == []
    assert sorted(p.stem for p in report.DATA.glob("*.json")) == sorted(report.RUNS)


def test_every_benchmark_is_reported():
    scripts = {p.name for p in (ROOT / "tools" / "bench").glob("*.py")}
    reported = {script for script, _, _ in report.RUNS.values()}
    assert scripts - set(report.HELPERS) == reported


def test_report_check_is_a_command():
    r = subprocess.run(
        [sys.executable, str(ROOT / "tools" / "bench" / "report.py"), "check"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert r.returncode == 0, r.stdout + r.stderr


def test_a_page_that_drifts_from_its_data_is_found(tmp_path, monkeypatch):
    pages = tmp_path / "benchmarks"
    (pages / "data").mkdir(parents=True)
    (pages / "data" / "pluto.json").write_text((report.DATA / "pluto.json").read_text())
    monkeypatch.setattr(report, "PAGES", pages)
    monkeypatch.setattr(report, "DATA", pages / "data")
    monkeypatch.setattr(report, "ROOT", tmp_path)
    report.write()
    assert report.stale() == []
    page = pages / "pluto.md"
    page.write_text(page.read_text().replace("| obsw |", "| obsw (typed) |", 1))
    assert report.stale() == ["benchmarks/pluto.md"]


def test_ratios_say_how_many_times_better_obsw_is():
    assert report.ratio(300.0, 100.0, True) == 3.0  # higher is better: 300/s against 100/s
    assert report.ratio(1.0, 4.0, False) == 4.0  # lower is better: 1 ms against 4 ms
    assert report.ratio(0, 4.0, False) is None


def test_figures_read_as_people_write_them():
    assert [report.fmt(v) for v in (1234567.8, 0.04911, 8.737, 99.73, 0, 12)] == [
        "1,234,568",
        "0.0491",
        "8.74",
        "99.7",
        "0",
        "12",
    ]


def test_the_conventions_list_what_the_imports_check_allows():
    text = (ROOT / "docs" / "conventions.md").read_text()
    section = text.split("## The MicroPython subset")[1].split("No `typing`")[0]
    listed = set(re.findall(r"`(\w+)`", section))
    assert listed == check_imports.MICROPYTHON_MODULES


def _json_blocks():
    for page in sorted((ROOT / "docs").rglob("*.md")):
        for body in re.findall(r"```json\n(.*?)```", page.read_text(), re.S):
            if body.startswith("--8<--"):  # a file of the repository, shown as it is
                path = body.split('"')[1]
                yield pathlib.Path(path), (ROOT / path).read_text()
            else:
                yield page.relative_to(ROOT), body


def test_every_json_example_parses():
    blocks = list(_json_blocks())
    assert len(blocks) >= 3
    for page, body in blocks:
        try:
            json.loads(body)
        except ValueError as e:
            raise AssertionError("%s: %s\n%s" % (page, e, body)) from None


def test_every_file_shown_exists():
    shown = []
    for page in sorted((ROOT / "docs").rglob("*.md")):
        shown += re.findall(r'^--8<-- "([^"]+)"$', page.read_text(), re.M)
    assert len(shown) >= 5
    assert [path for path in shown if not (ROOT / path).is_file()] == []


def test_the_obc_configurations_shown_are_accepted(tmp_path):
    configs = [(page, json.loads(b)) for page, b in _json_blocks() if '"processes"' in b]
    assert {str(page) for page, _ in configs} == {
        "examples/sample/mission.json",
        "docs/topology.md",
        "boards/raspberry-pi/mission.json",
        "docs/mission.md",
        "docs/fly-your-own-spacecraft.md",
        "docs/plug-ins.md",
    }
    for page, doc in configs:
        config = MissionConfig(doc, str(tmp_path / "mission.json"))
        assert config.processes == doc["processes"], page
