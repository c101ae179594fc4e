"""Freeze manifests that cannot be wrong: every module an image's entry point imports, directly
or not (lazy imports inside functions too), is in the image's manifest."""

import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))

import mpy  # noqa: E402

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
