"""Freeze manifests that cannot be wrong: every module an image's entry point imports, directly
or not (lazy imports inside functions too), is in the image's manifest."""

import pathlib

from obsw_host import mpy

ROOT = pathlib.Path(__file__).resolve().parents[2]

ROOTS = [ROOT / "micropython", ROOT / "boards" / "common", ROOT / "boards" / "OBSW_RECONFIG"]
IMAGES = {
    "reconfig.py": [ROOT / "boards" / "OBSW_RECONFIG" / "reconfig_main.py"],
    "qemu.py": [
        ROOT / "tools" / "upy" / "obsw_heap.py",
        ROOT / "tools" / "upy" / "obsw_run_tests.py",
    ],
}


def test_every_imported_module_is_frozen():
    for manifest, entries in IMAGES.items():
        missing = mpy.missing_from_manifest(ROOT / "manifests" / manifest, entries, ROOTS)
        assert missing == [], "%s misses %s" % (manifest, missing)


def test_the_reconfiguration_closure_is_the_application():
    found = mpy.import_closure(IMAGES["reconfig.py"], ROOTS)
    assert "obsw.reconfig.app" in found and "obsw.frames.tm_plan" in found
    assert "hal_pyb" in found
    assert not any(m.startswith(("obsw.pus.", "obsw.pluto.", "obsw.cfdp.")) for m in found)


def test_a_missing_module_is_found(tmp_path):
    m = tmp_path / "m.py"
    m.write_text(
        'metadata(version="0")\n'
        'module("obsw/__init__.py", base_path="%s")\n' % (ROOT / "micropython")
    )
    entry = tmp_path / "main.py"
    entry.write_text("def f():\n    from obsw.frames import tm_plan\n")
    missing = mpy.missing_from_manifest(m, [entry], ROOTS)
    assert "obsw.frames" in missing and "obsw.frames.tm_plan" in missing
    assert "obsw" not in missing


def _frozen(manifest):
    m = mpy.Manifest()
    m.execute(manifest)
    return m


def test_the_core_is_composed_of_one_manifest_per_package():
    lib = ROOT / "manifests" / "lib"
    packages = sorted(p.parent.name for p in lib.glob("*/manifest.py"))
    assert "obsw" in packages and len(packages) > 8
    owner = {}
    for name in packages:
        path = lib / name / "manifest.py"
        first = path.read_text().split("\n", 1)[0]
        assert first.startswith("metadata("), path  # micropython-lib: metadata comes first
        for module in _frozen_here(path):
            assert module not in owner, "%s frozen by %s and %s" % (module, owner[module], name)
            owner[module] = name
    core = _frozen(ROOT / "manifests" / "core.py")
    frozen = sorted(target for _, target in core.modules)
    on_disk = sorted(
        str(p.relative_to(ROOT / "micropython"))
        for p in (ROOT / "micropython" / "obsw").rglob("*.py")
    )
    assert frozen == on_disk  # every core module, each once
    assert set(core.required) == set(packages)


def _frozen_here(path):
    """The modules ``path`` itself freezes (not those of the packages it requires)."""
    m = mpy.Manifest()
    m._require = lambda *a, **k: None
    m.execute(path)
    return [target for _, target in m.modules]


def test_the_reconfiguration_image_requires_only_what_it_needs():
    m = _frozen(ROOT / "manifests" / "reconfig.py")
    assert "obsw-reconfig" in m.required and "obsw-pus" not in m.required
    assert not any(t.startswith(("obsw/pus/", "obsw/pluto/", "obsw/cfdp/")) for _, t in m.modules)


def test_a_mission_manifest_adds_its_component_to_the_core(tmp_path):
    (tmp_path / "magnetorquer.py").write_text("class Torquer:\n    pass\n")
    mission = tmp_path / "manifest.py"
    mission.write_text(
        'metadata(version="1.0", description="a mission image")\n'
        'add_library("obsw", "$(OBSW)/manifests/lib")\n'
        'require("obsw", library="obsw")\n'
        'module("magnetorquer.py")\n'
    )
    m = _frozen(mission)
    frozen = [t for _, t in m.modules]
    assert "magnetorquer.py" in frozen and "obsw/pus/app.py" in frozen
    assert len(frozen) == len(set(frozen))


def test_a_package_calls_metadata_once(tmp_path):
    """As MicroPython's manifestfile.py: include() shares the includer's metadata, so an image
    that includes another image's manifest (both with metadata) is refused; require() does not."""
    bad = tmp_path / "bad.py"
    bad.write_text('metadata(version="1")\ninclude("%s")\n' % (ROOT / "manifests" / "core.py"))
    try:
        _frozen(bad)
    except ValueError as e:
        assert "metadata" in str(e)
    else:
        raise AssertionError("a second metadata() was accepted")
    for image in ("core.py", "unix.py", "qemu.py", "reconfig.py"):
        _frozen(ROOT / "manifests" / image)
