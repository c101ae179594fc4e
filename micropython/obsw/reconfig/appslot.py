"""The reconfiguration module's application update: modules from a verified slot on the
board's filesystem take the place of the image's frozen ones, tried, kept or given up.

A board runs its application frozen in flash; its RAM (a Pyboard's 103 KiB heap) cannot hold
the whole application as loaded modules, so an update replaces modules one by one: a signed
package (``obsw.update.package``, target ``reconfig``) carries the changed modules compiled
with mpy-cross (``obsw/reconfig/app.mpy``, ...), in the order they are to be loaded (a module
after those it imports). It is staged into ``app/`` beside its boot record ``app.json``::

    {"version": "1.1", "state": "trial" | "good" | "failed", "starts": N, "reason": TEXT}

``stage`` unpacks and checks the package in ``app.part/`` (a package refused changes nothing),
then removes the record (from then on the frozen application boots), renames ``app.part/``
``app/`` and writes the record ``trial``: a power cut at any step leaves the slot and record
as they were, no record, or a complete, verified slot on trial. ``boot`` is the board's boot
selector (``reconfig_main``): if the record says ``good``, or ``trial`` for at most
``max_starts`` starts (a watchdog reset of a hung trial is a start that never confirmed), it
loads the slot's modules under their names, so the application's imports find them, then
starts the application; otherwise, or when a slot module or the application raises, the
frozen application starts, after the record says why. The application calls ``confirm`` once
it has run healthy: the trial becomes ``good``. Records are written whole (renamed over).
"""

import json
import os
import sys

from obsw.update.package import Reader

SLOT = "app"
RECORD = "app.json"
_PART = ".part"


def _join(*parts):
    return "/".join(p.rstrip("/") for p in parts if p)


def _exists(path):
    try:
        os.stat(path)
        return True
    except OSError:
        return False


def _is_dir(path):
    try:
        return os.stat(path)[0] & 0x4000 != 0
    except OSError:
        return False


def remove_tree(path):
    """Remove ``path`` and all under it (nothing if it is not there)."""
    if _is_dir(path):
        for name in os.listdir(path):
            remove_tree(_join(path, name))
        os.rmdir(path)
    elif _exists(path):
        os.remove(path)


def _makedirs(path):
    here = "/" if path.startswith("/") else ""
    for part in path.split("/"):
        if not part:
            continue
        here = here + part if here in ("", "/") else here + "/" + part
        if not _is_dir(here):
            os.mkdir(here)


def read(root):
    """The boot record at ``root`` (a dict), or None."""
    try:
        with open(_join(root, RECORD)) as f:
            record = json.load(f)
    except (OSError, ValueError):
        return None
    return record if isinstance(record, dict) else None


def write(root, record):
    path = _join(root, RECORD)
    with open(path + _PART, "w") as f:
        f.write(json.dumps(record))
    os.rename(path + _PART, path)


def stage(root, stream, verify, key, mission):
    """Install the package read from ``stream`` as the slot on trial; its manifest. A package
    that fails a check raises its ``PackageError`` and changes nothing: what ran runs."""
    part = _join(root, SLOT + _PART)
    remove_tree(part)
    reader = Reader(stream, verify, key, mission, "reconfig")
    out = [None, None]  # path, open file

    def put(path, chunk):
        if out[0] != path:
            target = _join(part, path)
            _makedirs(target[: target.rfind("/")])
            out[0], out[1] = path, open(target, "wb")
        if chunk is None:
            out[1].close()
            out[0] = None
        else:
            out[1].write(chunk)

    try:
        reader.files(put)
        if len(reader.manifest["files"]) != len(reader.manifest["tree"]):
            from obsw.update.package import BadManifest

            raise BadManifest("a delta: the module takes full packages only")
    except Exception:
        if out[0] is not None:
            out[1].close()
        remove_tree(part)
        raise
    with open(_join(part, "manifest.json"), "wb") as f:
        f.write(reader.manifest_bytes)
    record = _join(root, RECORD)
    if _exists(record):  # from here until the new record, the frozen application boots
        os.remove(record)
    remove_tree(_join(root, SLOT))
    os.rename(part, _join(root, SLOT))
    version = reader.manifest["version"]
    write(root, {"version": version, "state": "trial", "starts": 0, "reason": ""})
    return reader.manifest


def choose(root, max_starts):
    """At a start: the slot's folder to run, or None for the frozen application."""
    record = read(root)
    if record is None or record.get("state") not in ("trial", "good"):
        return None
    if not _is_dir(_join(root, SLOT)):
        fail(root, "the slot is gone")
        return None
    if record["state"] == "trial":
        record["starts"] = record.get("starts", 0) + 1
        if record["starts"] > max_starts:
            record["state"] = "failed"
            record["reason"] = "did not confirm in %d starts" % max_starts
            write(root, record)
            return None
        write(root, record)
    return _join(root, SLOT)


def confirm(root):
    """The application runs healthy: a trial's version is kept. True if it was on trial."""
    record = read(root)
    if record is None or record.get("state") != "trial":
        return False
    record["state"] = "good"
    write(root, record)
    return True


def fail(root, reason):
    record = read(root) or {"version": "", "starts": 0}
    record["state"] = "failed"
    record["reason"] = reason
    write(root, record)


def running(root):
    """(version, state) of the slot, or None: what ``boot`` decided at this start."""
    record = read(root)
    return (record.get("version"), record.get("state")) if record else None


def _forget():
    """Drop the imported ``obsw`` modules, so the next imports find them on ``sys.path``
    again (this module goes on working: its code is held by the caller)."""
    for name in list(sys.modules):
        if name == "obsw" or name.startswith("obsw."):
            del sys.modules[name]


def _load(path, module_file):
    """Load ``module_file`` (``obsw/reconfig/app.mpy``) of the slot at ``path`` as module
    ``obsw.reconfig.app``, in place of the frozen one; returns its name."""
    folder, _, leaf = module_file.rpartition("/")
    short = leaf.rpartition(".")[0]
    dotted = (folder.replace("/", ".") + "." if folder else "") + short
    saved_path, shadowed = sys.path[:], sys.modules.pop(short, None)
    sys.path[:] = [_join(path, folder)]  # only the slot's folder: never the frozen module
    try:
        module = __import__(short)
    finally:
        sys.path[:] = saved_path
        sys.modules.pop(short, None)
        if shadowed is not None:
            sys.modules[short] = shadowed
    sys.modules[dotted] = module
    parent = sys.modules.get(dotted.rpartition(".")[0])
    if parent is not None:
        setattr(parent, short, module)
    return dotted


def boot(root, start, max_starts=2, out=print):
    """The boot selector: ``start()`` imports and runs the application (it does not return
    while it runs), with the slot's modules if ``choose`` says so, else (or after a slot
    module or the application raised) the frozen ones."""
    path = choose(root, max_starts)
    if path is not None:
        record = read(root)
        out("application %s from %s (%s)" % (record.get("version"), path, record.get("state")))
        try:
            with open(_join(path, "manifest.json")) as f:
                files = json.load(f)["files"]
            for entry in files:  # in the package's order: a module after those it imports
                _load(path, entry["path"])
            return start()
        except Exception as e:  # the new application cannot run: the frozen one does
            _forget()
            fail(root, "%s: %s" % (type(e).__name__, e))
            out("application from %s failed (%s: %s): the frozen one starts" % (
                path, type(e).__name__, e))  # fmt: skip
    return start()
