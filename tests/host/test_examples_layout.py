"""Demos and samples live in examples/, outside the product: no product module imports them."""

import ast
import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"


def _imports(path):
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            yield node.module


def test_product_code_never_imports_examples():
    example_modules = {p.stem for p in EXAMPLES.glob("*.py")} | {"examples"}
    assert "pus_demo" in example_modules  # the examples are where this test expects them
    bad = []
    for folder in ("host", "micropython"):
        for path in sorted((ROOT / folder).rglob("*.py")):
            for name in _imports(path):
                top = name.split(".")[0]
                if top in example_modules or name.startswith("obsw_host.examples"):
                    bad.append("%s imports %s" % (path.relative_to(ROOT), name))
    assert bad == []


def test_no_demo_module_left_in_the_product():
    left = [
        str(p.relative_to(ROOT))
        for folder in ("host", "micropython")
        for p in (ROOT / folder).rglob("*demo*.py")
    ]
    assert left == []
