"""Check the dependency rule: micropython/ imports only what MicroPython has, nothing from host/.

Prints one line per offending import and a closing 'N passed, N failed' (modules checked).
"""

import ast
import pathlib
import sys

# What the MicroPython ports the project targets provide (docs/conventions.md, "The MicroPython
# subset").
MICROPYTHON_MODULES = {
    "array",
    "asyncio",
    "binascii",
    "collections",
    "errno",
    "gc",
    "hashlib",
    "io",
    "json",
    "math",
    "micropython",
    "os",
    "random",
    "re",
    "select",
    "socket",
    "struct",
    "sys",
    "time",
}
# Only compat may try an import that MicroPython lacks, inside `try: ... except ImportError`.
COMPAT = "compat.py"


def _guarded(node, parents):
    for p in parents:
        if isinstance(p, ast.Try):
            for h in p.handlers:
                names = h.type.elts if isinstance(h.type, ast.Tuple) else [h.type]
                if any(isinstance(n, ast.Name) and n.id == "ImportError" for n in names):
                    return True
    return False


def _imports(tree):
    stack = [(tree, [])]
    while stack:
        node, parents = stack.pop()
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield node, alias.name.split(".")[0], parents
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                yield node, ".", parents
            else:
                yield node, node.module.split(".")[0], parents
        for child in ast.iter_child_nodes(node):
            stack.append((child, parents + [node]))


def check(root):
    problems = []
    files = sorted(pathlib.Path(root).rglob("*.py"))
    for path in files:
        tree = ast.parse(path.read_text(), str(path))
        for node, top, parents in _imports(tree):
            if top == "obsw" or top in MICROPYTHON_MODULES:
                continue
            if top == ".":
                why = "relative import (use absolute `from obsw... import`)"
            elif path.name == COMPAT and _guarded(node, parents):
                continue
            elif top in ("obsw_host", "boards", "tests", "tools"):
                why = "core must not import %s" % top
            else:
                why = "MicroPython has no module %r" % top
            problems.append((path, node.lineno, why))
    return files, problems


def main(argv):
    root = argv[1] if len(argv) > 1 else "micropython"
    files, problems = check(root)
    bad = {p for p, _, _ in problems}
    for path, line, why in problems:
        print("%s:%d: %s" % (path, line, why))
    print("imports: %d passed, %d failed" % (len(files) - len(bad), len(bad)))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
