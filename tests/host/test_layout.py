"""The dependency rule of the source tree (ARCHITECTURE.md), checked on every run."""

import ast
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _top_imports(folder):
    for path in sorted((ROOT / folder).rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                for alias in node.names:
                    yield path, alias.name.split(".")[0]
            elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
                yield path, node.module.split(".")[0]


def test_core_imports_only_what_micropython_has():
    res = subprocess.run(
        [sys.executable, str(ROOT / "tools" / "check_imports.py"), str(ROOT / "micropython")],
        capture_output=True,
        text=True,
    )
    assert res.returncode == 0, res.stdout + res.stderr
    assert " 0 failed" in res.stdout


def test_check_imports_rejects_host_and_cpython_only_modules(tmp_path):
    core = tmp_path / "obsw"
    core.mkdir()
    (core / "bad.py").write_text("import typing\nfrom obsw_host import cli\nfrom . import x\n")
    res = subprocess.run(
        [sys.executable, str(ROOT / "tools" / "check_imports.py"), str(tmp_path)],
        capture_output=True,
        text=True,
    )
    assert res.returncode == 1
    assert "no module 'typing'" in res.stdout
    assert "must not import obsw_host" in res.stdout
    assert "relative import" in res.stdout


def test_boards_and_host_do_not_import_tests_or_tools():
    for folder in ("boards", "host"):
        for path, top in _top_imports(folder):
            assert top not in ("tests", "tools"), "%s imports %s" % (path, top)


def test_boards_do_not_import_host():
    for path, top in _top_imports("boards"):
        assert top != "obsw_host", "%s imports obsw_host" % path


def test_every_manifest_starts_with_metadata():
    manifests = sorted((ROOT / "manifests").glob("*.py"))
    assert manifests
    for m in manifests:
        first = ast.parse(m.read_text()).body[0]
        assert isinstance(first, ast.Expr) and first.value.func.id == "metadata", m
