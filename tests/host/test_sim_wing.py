"""The rigs live in ``obsw_sim``: the product package never imports them, nor privates of
another of its modules through ``from x import _y``."""

import ast
import os

HOST = os.path.join(os.path.dirname(__file__), "..", "..", "host", "obsw_host")


def _imports():
    for folder, _, files in os.walk(HOST):
        for name in files:
            if name.endswith(".py"):
                path = os.path.join(folder, name)
                with open(path, encoding="utf-8") as f:
                    tree = ast.parse(f.read(), path)
                for node in ast.walk(tree):
                    if isinstance(node, ast.Import):
                        for a in node.names:
                            yield path, a.name, None
                    elif isinstance(node, ast.ImportFrom) and node.module:
                        for a in node.names:
                            yield path, node.module, a.name


def test_the_product_never_imports_the_rigs():
    found = [(p, m) for p, m, _ in _imports() if m == "obsw_sim" or m.startswith("obsw_sim.")]
    assert found == []


def test_no_private_name_is_imported_from_another_module():
    found = [
        (os.path.relpath(p, HOST), m, n)
        for p, m, n in _imports()
        if n and n.startswith("_") and not n.startswith("__") and m.startswith("obsw")
    ]
    assert found == []
