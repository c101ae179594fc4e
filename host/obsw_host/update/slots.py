"""The OBC's software: the factory version, two slots, and the boot record that says which runs.

``<state>/software/`` holds slots ``a`` and ``b`` (each ``lib/`` with the ``obsw`` and
``obsw_host`` packages, ``mission/`` and the package's ``manifest.json``) and ``boot.json``,
the boot record::

    {"active": "factory" | "a" | "b",     what runs when no trial is on
     "previous": the slot active before it (a ground rollback goes back there), or null
     "staged": a verified slot waiting for activation, or null
     "trial": {"slot": S, "starts": N} while a new version has to prove itself, or null
     "seq": N, "reported": N, "log": [{"seq", "event", "version", "reason"}, ..]}

The factory version is the software installed with the OBC (its ``obsw obc serve``); it is
never overwritten, so there is always a version to fall back on. Every change of the record is
one atomic write (``os.replace`` of a fsynced file) under a lock, and staging only ever writes
the slot that is neither active nor on trial (building it in ``<slot>.part`` and renaming it),
so a power cut at any step leaves the record naming a complete, verified version.

The steps: ``stage`` (a package from the onboard filestore into the free slot, verified),
``activate`` (the staged slot goes on trial), ``choose`` (at every start of the platform
manager: the trial's slot, counting its starts, or after ``max_starts`` the active one again),
``confirm`` (the trial's version reported healthy: it becomes the active one), ``rollback``
(a failed trial ends, or the ground goes back to the previous version). Each step appends to
the log, whose entries the ``Software`` component raises as events until ``reported``.
"""

import fcntl
import json
import os
import shutil

from obsw import jsonsafe
from obsw.update.package import (
    BadManifest,
    HashMismatch,
    PackageError,
    Reader,
    check_floor,
    sha256_hex,
    version_key,
)

FACTORY = "factory"
SLOTS = ("a", "b")
_LOG_KEEP = 32


class UpdateRefused(Exception):
    """A step that cannot be taken now (``code``: the failure's name, the text says why)."""

    def __init__(self, code, text):
        super().__init__(text)
        self.code = code


def _fresh():
    return {"active": FACTORY, "previous": None, "staged": None, "trial": None,
            "seq": 0, "reported": 0, "log": []}  # fmt: skip


_MAX_RECORD = 1 << 20  # octets: the log is trimmed far below this


def _check_record(record):
    """ValueError unless ``record`` is a boot record every step can read."""
    if not isinstance(record, dict):
        raise ValueError("expected an object")
    slots = (None, FACTORY) + tuple(SLOTS)
    if record.get("active") not in slots[1:]:
        raise ValueError("active: %r" % (record.get("active"),))
    for k in ("previous", "staged"):
        if record.get(k) not in slots:
            raise ValueError("%s: %r" % (k, record.get(k)))
    trial = record.get("trial")
    if trial is not None and not (
        isinstance(trial, dict)
        and trial.get("slot") in SLOTS
        and isinstance(trial.get("starts"), int)
    ):
        raise ValueError("trial: %r" % (trial,))
    for k in ("seq", "reported"):
        if not isinstance(record.get(k), int) or isinstance(record.get(k), bool):
            raise ValueError("%s: %r" % (k, record.get(k)))
    if not isinstance(record.get("log"), list):
        raise ValueError("log: expected a list")


def _write_atomic(path, data):
    part = path + ".part"
    with open(part, "wb") as f:
        f.write(data)
        f.flush()
        os.fsync(f.fileno())
    os.replace(part, path)


def _sync_dir(path):
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


class Software:
    """The software folder ``root`` (``<state>/software``); ``factory``: the installed
    version's name; ``mission_dir``: the factory's mission folder."""

    def __init__(self, root, factory, mission_dir):
        self.root = root
        self.factory = factory
        self.mission_dir = mission_dir
        self.path = os.path.join(root, "boot.json")
        os.makedirs(root, exist_ok=True)

    # ---------------------------------------------------------------------- the record

    def read(self):
        try:
            with open(self.path, "rb") as f:
                text = f.read(_MAX_RECORD + 1)
        except OSError:
            return _fresh()
        try:
            if len(text) > _MAX_RECORD:
                raise ValueError("larger than %d bytes" % _MAX_RECORD)
            record = jsonsafe.loads(text.decode())
            _check_record(record)
        except ValueError as e:  # cannot happen with atomic writes; if it does: the factory
            try:  # the bad record kept aside for the ground to look at, never read again
                os.replace(self.path, self.path + ".bad")
            except OSError:
                pass
            record = _fresh()
            self._log(record, "rolled_back", self.factory, "boot record unreadable: %s" % e)
        return record

    def _lock(self):
        fd = os.open(os.path.join(self.root, "boot.lock"), os.O_RDWR | os.O_CREAT, 0o644)
        fcntl.flock(fd, fcntl.LOCK_EX)
        return fd

    def _change(self, step):
        """Run ``step(record)`` under the lock and write the record it changed; its value."""
        fd = self._lock()
        try:
            record = self.read()
            result = step(record)
            _write_atomic(self.path, json.dumps(record, sort_keys=True).encode())
            return result
        finally:
            os.close(fd)

    def _log(self, record, event, version, reason=""):
        record["seq"] += 1
        record["log"].append(
            {"seq": record["seq"], "event": event, "version": version, "reason": reason}
        )
        del record["log"][:-_LOG_KEEP]

    # ---------------------------------------------------------------------- versions

    def slot_dir(self, slot):
        return os.path.join(self.root, slot)

    def version(self, slot):
        """The version in ``slot`` (None if the slot holds none)."""
        if slot == FACTORY:
            return self.factory
        manifest = self.manifest(slot)
        return manifest["version"] if manifest else None

    def manifest(self, slot):
        try:
            with open(os.path.join(self.slot_dir(slot), "manifest.json"), "rb") as f:
                return json.loads(f.read())
        except (OSError, ValueError):
            return None

    def code(self, slot):
        """(lib folder or None for the factory's, mission file) of ``slot``."""
        if slot == FACTORY:
            return None, None
        d = self.slot_dir(slot)
        mission = os.path.join(d, "mission", "mission.json")
        return os.path.join(d, "lib"), mission if os.path.exists(mission) else None

    def running_here(self):
        """The slot whose code this process runs (its ``obsw_host`` package is there)."""
        import obsw_host

        here = os.path.realpath(obsw_host.__file__)
        for slot in SLOTS:
            if here.startswith(os.path.realpath(self.slot_dir(slot)) + os.sep):
                return slot
        return FACTORY

    def running(self, record=None):
        """The slot that runs now: the trial's, else the active one."""
        record = record or self.read()
        return record["trial"]["slot"] if record["trial"] else record["active"]

    # ---------------------------------------------------------------------- the steps

    def stage(self, package, verify, key, mission):
        """Verify ``package`` (a path) and install it into the free slot; its manifest.
        A package that fails a check is removed (PackageError, logged ``refused``)."""

        def free(record):
            if record["trial"]:
                raise UpdateRefused("trial_running", "a new version is on trial: wait for it")
            busy = {record["active"]}
            slot = [s for s in SLOTS if s not in busy][0]
            if record["previous"] == slot:
                record["previous"] = None  # its old version is about to be overwritten
            if record["staged"] == slot:
                record["staged"] = None
            return slot, record["active"]

        slot, active = self._change(free)
        part = self.slot_dir(slot) + ".part"
        shutil.rmtree(part, ignore_errors=True)
        try:
            manifest = self._unpack(package, part, active, verify, key, mission)
        except (PackageError, OSError) as e:
            shutil.rmtree(part, ignore_errors=True)
            try:
                os.remove(package)
            except OSError:
                pass
            reason = "%s: %s" % (getattr(e, "code", "unreadable"), e)
            self._change(lambda r: self._log(r, "refused", "", reason))
            raise
        final = self.slot_dir(slot)
        shutil.rmtree(final, ignore_errors=True)
        os.rename(part, final)
        _sync_dir(self.root)

        def staged(record):
            record["staged"] = slot
            self._log(record, "staged", manifest["version"])

        self._change(staged)
        return manifest

    # ---------------------------------------------------------------------- anti-rollback

    def floor(self):
        """The oldest version this OBC takes: the newest it has confirmed (kept in
        ``floor``, written before the boot record says so), never below the factory's."""
        best = self.factory
        try:
            with open(os.path.join(self.root, "floor"), "rb") as f:
                text = f.read(256).decode().strip()
            if text and version_key(text) > version_key(best):
                best = text
        except (OSError, ValueError):
            pass
        return best

    def _raise_floor(self, version):
        if version and version_key(version) > version_key(self.floor()):
            _write_atomic(os.path.join(self.root, "floor"), version.encode())
            _sync_dir(self.root)

    def _unpack(self, package, part, active, verify, key, mission):
        with open(package, "rb") as stream:
            reader = Reader(stream, verify, key, mission, "obc")
            m = check_floor(reader.manifest, self.floor())
            if m["base"] is not None and m["base"] != self.version(active):
                raise BadManifest("a delta to version %s, the OBC runs %s" % (
                    m["base"], self.version(active)))  # fmt: skip
            files = {}

            def write(path, chunk):
                f = files.get(path)
                if f is None:
                    target = os.path.join(part, *path.split("/"))
                    os.makedirs(os.path.dirname(target), exist_ok=True)
                    f = files[path] = open(target, "wb")
                if chunk is None:
                    f.flush()
                    os.fsync(f.fileno())
                    f.close()
                else:
                    f.write(chunk)

            try:
                reader.files(write)
            finally:
                for f in files.values():
                    f.close()
        carried = {f["path"] for f in m["files"]}
        for path, digest in m["tree"].items():  # a delta's other files: from the running one
            if path in carried:
                continue
            src = self._source(active, path)
            with open(src, "rb") as f:
                data = f.read()
            if sha256_hex(data) != digest:
                raise HashMismatch("file %s of the running version is not the base's" % path)
            target = os.path.join(part, *path.split("/"))
            os.makedirs(os.path.dirname(target), exist_ok=True)
            _write_atomic(target, data)
        _write_atomic(os.path.join(part, "manifest.json"), reader.manifest_bytes)
        return m

    def _source(self, slot, path):
        """Where file ``path`` of a package's tree is in ``slot``."""
        if slot != FACTORY:
            return os.path.join(self.slot_dir(slot), *path.split("/"))
        import obsw

        import obsw_host

        top, _, rest = path.partition("/")
        if top == "mission":
            return os.path.join(self.mission_dir, *rest.split("/"))
        package, _, rest = rest.partition("/")
        roots = {"obsw": obsw.__file__, "obsw_host": obsw_host.__file__}
        if top != "lib" or package not in roots:
            raise HashMismatch("file %s is not in the running version" % path)
        return os.path.join(os.path.dirname(roots[package]), *rest.split("/"))

    def activate(self):
        """The staged slot goes on trial at the next start; its version."""

        def step(record):
            slot = record["staged"]
            if not slot:
                raise UpdateRefused("nothing_staged", "no staged version to activate")
            if record["trial"]:
                raise UpdateRefused("trial_running", "a new version is on trial already")
            record["staged"] = None
            record["trial"] = {"slot": slot, "starts": 0}
            self._log(record, "activated", self.version(slot))
            return self.version(slot)

        return self._change(step)

    def choose(self, max_starts):
        """At a start: (slot to run, on trial?). A trial past ``max_starts`` starts is over."""
        for name in os.listdir(self.root):  # a staging or a swap a power cut interrupted
            if name.endswith(".part") and name[:-5] in SLOTS:
                shutil.rmtree(os.path.join(self.root, name), ignore_errors=True)

        def step(record):
            trial = record["trial"]
            if trial:
                trial["starts"] += 1
                if self.version(trial["slot"]) is None:
                    self._end_trial(record, "its slot is gone")
                elif trial["starts"] > max_starts:
                    self._end_trial(record, "did not come up in %d starts" % max_starts)
                else:
                    return trial["slot"], True
            if record["active"] != FACTORY and self.version(record["active"]) is None:
                self._log(
                    record, "rolled_back", self.factory, "slot %s is gone" % record["active"]
                )
                record["active"], record["previous"] = FACTORY, None
            return record["active"], False

        return self._change(step)

    def _end_trial(self, record, reason):
        slot = record["trial"]["slot"]
        record["trial"] = None
        self._log(record, "rolled_back", self.version(slot) or "", reason)

    def confirm(self):
        """The trial's version reported healthy: it is the active one from now on."""

        def step(record):
            trial = record["trial"]
            if not trial:
                return None
            self._raise_floor(self.version(trial["slot"]))  # no going below it from now on
            record["previous"], record["active"] = record["active"], trial["slot"]
            record["trial"] = None
            self._log(record, "confirmed", self.version(trial["slot"]))
            return trial["slot"]

        return self._change(step)

    def fail_trial(self, reason):
        """The trial's version did not report healthy: back to the active one."""

        def step(record):
            if record["trial"]:
                self._end_trial(record, reason)
                return True
            return False

        return self._change(step)

    def fall_back(self, reason):
        """What runs cannot run (a trial's or the active version): the one before it."""

        def step(record):
            if record["trial"]:
                self._end_trial(record, reason)
                return
            active = record["active"]
            back = record["previous"] if self.version(record["previous"] or FACTORY) else None
            record["active"], record["previous"] = back or FACTORY, None
            self._log(record, "rolled_back", self.version(active) or "", reason)

        self._change(step)

    def rollback(self):
        """The ground goes back: a trial ends, else the previous version becomes active."""

        def step(record):
            if record["trial"]:
                self._end_trial(record, "the ground rolled back")
                return record["active"]
            previous = record["previous"]
            if not previous or self.version(previous) is None:
                raise UpdateRefused("no_previous", "no previous version to roll back to")
            record["previous"], record["active"] = record["active"], previous
            self._log(record, "rolled_back", self.version(previous), "the ground rolled back")
            return previous

        return self._change(step)

    def unreported(self):
        """Log entries not yet raised as events, and a function that marks them raised."""
        record = self.read()
        new = [e for e in record["log"] if e["seq"] > record["reported"]]

        def done():
            def step(r):
                r["reported"] = max(r["reported"], new[-1]["seq"])

            if new:
                self._change(step)

        return new, done
