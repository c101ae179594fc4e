"""``Software``: the OBC's software update component, served by the PUS process.

Its functions (service 8) are the ground's: ``stage(file)`` verifies a package that CFDP
brought into the onboard filestore and installs it into the free slot; ``activate()`` puts
the staged version on trial (the platform manager restarts the units from it);
``rollback()`` ends a trial or goes back to the previous version. ``self_test()`` is the
platform manager's: it checks every file of the running version against the hashes its
package signed and runs the mission's own test (``update.self_test``: ``module:function``,
which raises to fail). Its attributes say what runs (``version``, ``slot``), what is staged
and how many starts the trial has had; every step of the boot record's log becomes an event
(``staged``, ``refused``, ``activated``, ``confirmed``, ``rolled_back``), raised once, even
when it happened while the PUS process was down (``obsw_host.update.slots``).
"""

import hashlib
import importlib
import os

from obsw.il.errors import ComponentError
from obsw.il.interface import DATA, INFO, LOW, MEDIUM, Attribute, Event, Interface, Operation
from obsw.update.package import PackageError

from obsw_host.update.slots import FACTORY, UpdateRefused

INBOX = "update"  # the onboard filestore's folder for packages on their way up

SOFTWARE = Interface(
    "Software",
    0x7E40,
    [
        Attribute("version", 1, DATA, type="str", description="the version running"),
        Attribute("slot", 2, DATA, type="str", description="factory, a or b"),
        Attribute("pending", 3, DATA, type="str", description="the version staged, or empty"),
        Attribute(
            "trial_starts", 4, DATA, type="u8", description="starts of the version on trial"
        ),
        Operation("stage", 5, ("file",), description="verify and install a package"),
        Operation("activate", 6, (), description="run the staged version on trial"),
        Operation("rollback", 7, (), description="end the trial, or go back a version"),
        Operation("self_test", 8, (), description="the running version's checks"),
        Operation("refresh", 9, (), description="raise the boot record's new steps"),
        Event("staged", 10, INFO, fields=("version",)),
        Event("refused", 11, MEDIUM, fields=("reason",)),
        Event("activated", 12, INFO, fields=("version",)),
        Event("confirmed", 13, INFO, fields=("version",)),
        Event("rolled_back", 14, LOW, fields=("version", "reason")),
    ],
    description="the OBC's software versions and their update (obsw_host.update)",
)


class SoftwareComponent:
    """The provider of ``SOFTWARE`` (see the module text): ``software`` is the state's
    ``slots.Software``, ``files`` the onboard filestore's root, ``key`` the mission's update
    public key (None: updates refused), ``mission`` its name, ``self_test`` the mission's
    ``module:function`` or None."""

    def __init__(self, software, files, key, mission, verify, self_test=None):
        self.software = software
        self.files = files
        self.key = key
        self.mission = mission
        self.verify = verify
        self.mission_test = self_test
        self.il = None
        os.makedirs(os.path.join(files, INBOX), exist_ok=True)  # where the ground puts packages
        self._show(software.read())

    def il_bind(self, provider):
        self.il = provider  # the PUS process calls refresh() once its events are bound

    def _set(self, name, value):
        if self.il is not None:
            self.il.update(name, value)
        else:
            setattr(self, name, value)

    def _show(self, record):
        slot = self.software.running_here()
        staged, trial = record["staged"], record["trial"]
        for name, value in (
            ("version", self.software.version(slot) or ""),
            ("slot", slot),
            ("pending", self.software.version(staged) or "" if staged else ""),
            ("trial_starts", trial["starts"] if trial and trial["slot"] == slot else 0),
        ):
            self._set(name, value)

    # ------------------------------------------------------------------- the ground's

    def stage(self, file):
        if self.key is None:
            raise ComponentError("NO_KEY", "the mission names no update key: updates refused")
        # only a package in the update folder: a refused one is removed, so any other file of
        # the filestore (an image, data) must never be taken
        inbox = os.path.realpath(os.path.join(self.files, INBOX))
        path = os.path.join(self.files, *str(file).strip("/").split("/"))
        if not os.path.realpath(path).startswith(inbox + os.sep):
            raise ComponentError(
                "BAD_FILE", "%s is not in the update folder %s/ of the filestore" % (file, INBOX)
            )
        if os.path.islink(path) or not os.path.isfile(path):
            raise ComponentError("NO_FILE", "no file %s in the onboard filestore" % file)
        try:
            manifest = self.software.stage(path, self.verify, self.key, self.mission)
        except PackageError as e:
            raise ComponentError(e.code.upper(), str(e)) from None
        except UpdateRefused as e:
            raise ComponentError(e.code.upper(), str(e)) from None
        except OSError as e:
            raise ComponentError("WRITE_FAILED", "staging failed: %s" % e) from None
        finally:
            self.refresh()
        return manifest["version"]

    def activate(self):
        try:
            version = self.software.activate()
        except UpdateRefused as e:
            raise ComponentError(e.code.upper(), str(e)) from None
        self.refresh()
        return version

    def rollback(self):
        try:
            slot = self.software.rollback()
        except UpdateRefused as e:
            raise ComponentError(e.code.upper(), str(e)) from None
        self.refresh()
        return self.software.version(slot)

    # ------------------------------------------------------------------- the platform's

    def self_test(self):
        slot = self.software.running_here()
        if slot != FACTORY:
            manifest = self.software.manifest(slot) or {}
            root = self.software.slot_dir(slot)
            for path, digest in sorted(manifest.get("tree", {}).items()):
                h = hashlib.sha256()
                try:
                    with open(os.path.join(root, *path.split("/")), "rb") as f:
                        h.update(f.read())
                except OSError:
                    raise ComponentError(
                        "SELF_TEST", "file %s of the version is missing" % path
                    ) from None
                if h.hexdigest() != digest:
                    raise ComponentError("SELF_TEST", "file %s of the version changed" % path)
        if self.mission_test:
            module, _, name = self.mission_test.partition(":")
            try:
                getattr(importlib.import_module(module), name)()
            except Exception as e:  # the mission's test failed: the version is not healthy
                raise ComponentError("SELF_TEST", "%s: %s: %s" % (
                    self.mission_test, type(e).__name__, e)) from None  # fmt: skip
        return True

    def refresh(self):
        """Raise the boot record's steps not raised yet; show the record."""
        new, done = self.software.unreported()
        if self.il is not None:
            for entry in new:
                fields = {"version": entry["version"], "reason": entry["reason"]}
                names = [f for f in ("version", "reason") if f in _FIELDS[entry["event"]]]
                self.il.emit(entry["event"], {k: fields[k] for k in names})
            done()
        self._show(self.software.read())
        return len(new)


_FIELDS = {m.name: m.fields for m in SOFTWARE.members.values() if isinstance(m, Event)}


def factory_version():
    """The version installed with the OBC (the package's metadata, else the source's)."""
    from importlib import metadata

    try:
        return metadata.version("obsw")
    except metadata.PackageNotFoundError:
        return "source"


def software_of(config):
    """The ``slots.Software`` of the OBC of ``config`` (its state folder's ``software``)."""
    from obsw_host.update.slots import Software

    mission_dir = os.path.dirname(os.path.abspath(config.path))
    return Software(os.path.join(config.state, "software"), factory_version(), mission_dir)


def build(config, update):
    """The ``SoftwareComponent`` of the OBC of ``config``; ``update``: its update section."""
    from obsw.update.signature import verify

    from obsw_host.update.build import load_public

    key = update["public_key"]
    if key is not None:
        key = load_public(os.path.join(os.path.dirname(os.path.abspath(config.path)), key))
    files = os.path.join(config.state, "files")
    return SoftwareComponent(
        software_of(config), files, key, config.name, verify, update["self_test"]
    )
