"""A copy of the sample spacecraft whose OBC is updated in flight, on this machine: the demo's
section and the update benchmark (tools/bench/update.py) use it.

    with UpdateRig(work) as rig:        # the sample in work/, an update key, its OBC running
        path, manifest, _ = rig.package("1.1")
        rig.upload(path)                # CFDP class 2 into the OBC's update folder
        rig.stage_and_activate(path)    # Software.stage and Software.activate (service 8)
        rig.until("confirmed", 60)      # the platform manager's verdict, in the boot record
"""

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time

from obsw_host import sample
from obsw_host.cfdp.client import CfdpClient
from obsw_host.mission.ids import MissionIds
from obsw_host.pus.ground import Ground
from obsw_host.update import build as b
from obsw_host.update.component import INBOX

DEADLINE = 30.0  # s a version on trial has to report healthy
HEALTHY_AFTER = 1.0
CRASH = {"lib/obsw_host/obc/assembly.py": "raise RuntimeError('this version is broken')\n"}


def free_base():
    for base in range(24000, 60000, 331):
        try:
            for offset in (10, 100, 101):
                with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
                    s.bind(("127.0.0.1", base + offset))
        except OSError:
            continue
        return base
    raise RuntimeError("no free port base")


def wait(predicate, timeout):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if predicate():
            return True
        time.sleep(0.02)
    return False


class UpdateRig:
    """The sample in ``work`` with an update key and small deadlines, its OBC, a ground."""

    def __init__(self, work):
        self.work = work
        self.folder = os.path.join(work, "sat")
        shutil.copytree(os.path.dirname(sample.MISSION_PATH), self.folder)
        b.keygen(os.path.join(work, "update.key"), allow_git=True)
        shutil.copy(os.path.join(work, "update.key.pub"), os.path.join(self.folder, "u.pub"))
        path = os.path.join(self.folder, "mission.json")
        with open(path) as f:
            doc = json.load(f)
        doc["ports"] = {"base": free_base()}
        doc["update"] = {"public_key": "u.pub", "deadline": DEADLINE,
                         "healthy_after": HEALTHY_AFTER}  # fmt: skip
        with open(path, "w") as f:
            json.dump(doc, f)
        self.key = b.load_private(os.path.join(work, "update.key"))
        self.public = bytes.fromhex(b.public_hex(self.key))
        self.ids = MissionIds.locate(self.folder)
        self.state = os.path.join(work, "state")
        self.record_path = os.path.join(self.state, "software", "boot.json")
        self.obc = None
        self.ground = Ground(self.ids.sdb, target=("127.0.0.1", self.ids.ports.pus), timeout=2.0)

    def package(self, version, replace=None, base=None):
        files = b.sources(self.folder)
        for path, text in (replace or {}).items():
            src = os.path.join(self.work, version + "-" + path.replace("/", "_"))
            with open(src, "w") as f:
                f.write(text)
            files[path] = src
        out = os.path.join(self.work, "v%s.obsw" % version)
        t = time.perf_counter()
        manifest = b.build(out, files, mission=self.ids.config.name, version=version,
                           key=self.key, base=base)  # fmt: skip
        return out, manifest, time.perf_counter() - t

    def start(self):
        obsw = os.path.join(os.path.dirname(sys.executable), "obsw")
        self.obc = subprocess.Popen([obsw, "obc", "serve", self.folder, "--state", self.state],
                                    stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                    start_new_session=True)  # fmt: skip
        if not wait(self._answers, 60):
            raise RuntimeError("the OBC did not come up")

    def _answers(self):
        try:
            return self.ground.ping(timeout=0.5).ok
        except Exception:
            return False

    def upload(self, path):
        """Seconds of the CFDP class 2 put into the onboard filestore's update folder."""
        sat, ground = self.ids.cfdp_entities
        root, name = os.path.split(path)
        with CfdpClient(ground, {sat: ("127.0.0.1", self.ids.ports.cfdp)}, root,
                        apid=self.ids.apid("cfdp"), cls=2, port=self.ids.ports.cfdp_ground,
                        timeout=120) as c:  # fmt: skip
            t = time.perf_counter()
            result = c.put(name, INBOX + "/" + name)
            took = time.perf_counter() - t
        if not result.delivered:
            raise RuntimeError(result.line())
        return took

    def stage_and_activate(self, path):
        name = os.path.basename(path)
        for function, args in (("Software.stage", {"file": INBOX + "/" + name}),
                               ("Software.activate", {})):  # fmt: skip
            if not self.ground.perform(function, timeout=30, **args).ok:
                raise RuntimeError("%s failed" % function)
        return time.monotonic()

    def record(self):
        try:
            with open(self.record_path) as f:
                return json.load(f)
        except (OSError, ValueError):
            return {}

    def until(self, event, timeout):
        seq = self.record().get("seq", 0)
        wait(lambda: any(e["seq"] > seq and e["event"] == event
                         for e in self.record().get("log", [])), timeout)  # fmt: skip
        return time.monotonic()

    def record_version(self):
        record = self.record()
        slot = (record.get("trial") or {}).get("slot") or record.get("active", "factory")
        if slot == "factory":
            return "the factory version"
        with open(os.path.join(self.state, "software", slot, "manifest.json")) as f:
            return json.load(f)["version"]

    def stop(self):
        if self.obc is not None:
            os.killpg(self.obc.pid, signal.SIGTERM)
            self.obc.wait(30)
        self.ground.close()

    def __enter__(self):
        self.start()
        return self

    def __exit__(self, *exc):
        self.stop()


def demo(out=print):
    """The demo's section: a new version confirmed, then a broken one rolled back."""
    import tempfile

    with tempfile.TemporaryDirectory(prefix="obsw-update-demo-") as work:
        with UpdateRig(work) as rig:
            out("the sample's OBC runs its factory version; the ground signs packages with an "
                "Ed25519 key whose public half is in the mission")  # fmt: skip
            path, manifest, _ = rig.package("1.1")
            out("package %s: %s, %d bytes" % (
                os.path.basename(path), b.describe(manifest), os.path.getsize(path)))  # fmt: skip
            out("uploaded by CFDP class 2 in %.2f s" % rig.upload(path))
            t0 = rig.stage_and_activate(path)
            out("Software.stage verified it into slot a; Software.activate put it on trial")
            rig.until("confirmed", DEADLINE + 60)
            out("1.1 confirmed %.1f s after activation: every process healthy, self-test passed"
                % (time.monotonic() - t0))  # fmt: skip
            base = b.base_manifest(path, rig.public, rig.ids.config.name, "obc")
            broken, manifest, _ = rig.package("1.2", CRASH, base)
            out("package 1.2, a delta of %d bytes whose OBC processes crash at start" % (
                os.path.getsize(broken)))  # fmt: skip
            rig.upload(broken)
            t0 = rig.stage_and_activate(broken)
            rig.until("rolled_back", DEADLINE + 60)
            entry = rig.record()["log"][-1]
            out("1.2 rolled back %.1f s after activation: %s" % (
                time.monotonic() - t0, entry["reason"]))  # fmt: skip
            out("the OBC runs %s again (slot %s)" % (
                rig.record_version(), rig.record()["active"]))  # fmt: skip
