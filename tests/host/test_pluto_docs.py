"""docs/pluto.md's Annex A table names, for every production, a test that exists."""

import ast
import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parents[2]
CORE = ROOT / "tests" / "core"


def _tests(path):
    """{class name: set of its test method names} of a test file."""
    tree = ast.parse(path.read_text())
    out = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            out[node.name] = {f.name for f in node.body if isinstance(f, ast.FunctionDef)}
    return out


def _table_rows():
    text = (ROOT / "docs" / "pluto.md").read_text()
    section = text.split("## The Annex A grammar against the parser", 1)[1].split("\n## ", 1)[0]
    return [line for line in section.splitlines() if line.startswith("| ") and "---" not in line]


def test_every_production_names_existing_tests():
    rows = _table_rows()[1:]  # past the header
    assert len(rows) >= 40
    for row in rows:
        cells = [c.strip() for c in row.strip("|").split("|")]
        production, supported, where = cells[0], cells[-2], cells[-1]
        assert supported in ("yes", "added") or supported.startswith("added"), row
        refs = re.findall(r"`([^`]+)`", where)
        assert refs or "annex_a" in where, "no test for %s" % production
        last_file = last_class = None
        for ref in refs:
            parts = ref.split("::")
            if parts[0].endswith(".py"):
                last_file, last_class = parts[0], None
                parts = parts[1:]
            assert last_file, ref
            classes = _tests(CORE / last_file)
            if len(parts) == 2:
                last_class = parts[0]
                assert parts[1] in classes[last_class], ref
            elif len(parts) == 1 and parts[0] in classes:
                last_class = parts[0]
            elif len(parts) == 1:
                assert last_class and parts[0] in classes[last_class], ref


def test_annex_a_procedure_exists():
    assert (ROOT / "tests" / "data" / "pluto" / "annex_a.pluto").exists()
