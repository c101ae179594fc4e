"""What a MicroPython freeze manifest freezes: enough of MicroPython's manifestfile.py
(``metadata``, ``include``, ``require`` with ``add_library``, ``package``, ``module``,
``freeze``) to list the modules, for the firmware tools and ``obsw board deploy``."""

import pathlib

# the source tree: a mission's manifest names it $(OBSW) (make MICROPY_MANIFEST_OBSW=...)
ROOT = pathlib.Path(__file__).resolve().parent.parent.parent


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
