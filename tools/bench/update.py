"""Benchmark of in-flight updates on a running OBC (`obsw obc serve` of a copy of the sample):
the size of a full package and of a one-module delta, the upload of the full one by CFDP class
2 over UDP (the sample link), and the time from activation to a confirmed version and to the
rollback of a version that crashes at start, next to the goal: the trial's deadline.

update.py [--quick] [--json]
"""

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path[:0] = [os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]

from obsw_host import sample  # noqa: E402
from obsw_host.cfdp.client import CfdpClient  # noqa: E402
from obsw_host.ids import MissionIds  # noqa: E402
from obsw_host.pus.ground import Ground  # noqa: E402
from obsw_host.update import build as b  # noqa: E402
from obsw_host.update.component import INBOX  # noqa: E402

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


class Rig:
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

    def stop(self):
        if self.obc is not None:
            os.killpg(self.obc.pid, signal.SIGTERM)
            self.obc.wait(30)
        self.ground.close()


def measure(quick):
    with tempfile.TemporaryDirectory(prefix="obsw-bench-update-") as work:
        rig = Rig(work)
        full, manifest, build_s = rig.package("1.1")
        key = bytes.fromhex(b.public_hex(rig.key))
        base = b.base_manifest(full, key, rig.ids.config.name, "obc")
        delta, _, _ = rig.package("1.2", {"lib/obsw_host/update_note.py": "NOTE = 1\n"}, base)
        broken, _, _ = rig.package("1.3", CRASH, base)
        rig.start()
        try:
            upload_s = rig.upload(full)
            seq = rig.record().get("seq", 0)
            t0 = rig.stage_and_activate(full)
            confirm_s = rig.until("confirmed", DEADLINE + 60) - t0
            if not any(e["seq"] > seq and e["event"] == "confirmed" for e in rig.record()["log"]):
                raise RuntimeError("1.1 was not confirmed")
            rollback_s = None
            if not quick:
                wait(rig._answers, 30)
                rig.upload(broken)
                t0 = rig.stage_and_activate(broken)
                rollback_s = rig.until("rolled_back", DEADLINE + 60) - t0
        finally:
            rig.stop()
        return {
            "full_bytes": os.path.getsize(full),
            "files": len(manifest["tree"]),
            "delta_bytes": os.path.getsize(delta),
            "build_s": build_s,
            "upload_s": upload_s,
            "confirm_s": confirm_s,
            "rollback_s": rollback_s,
        }


def main(argv):
    quick = "--quick" in argv
    m = measure(quick)
    rows = [
        ("package size: a one-module delta vs the full one (%d files)" % m["files"],
         m["delta_bytes"], m["full_bytes"], "B"),
        ("upload of the full package, CFDP class 2 over UDP", m["upload_s"], DEADLINE, "s"),
        ("activation to confirmed (healthy_after %.0f s)" % HEALTHY_AFTER, m["confirm_s"],
         DEADLINE, "s"),
    ]  # fmt: skip
    if m["rollback_s"] is not None:
        rows.append(("activation to rollback of a version that crashes at start",
                     m["rollback_s"], DEADLINE, "s"))  # fmt: skip
    if "--json" in argv:
        out = []
        for case, ours, ref, unit in rows:
            for impl, value in (("obsw", ours), ("reference", ref)):
                out.append({"case": case, "impl": impl, "value": value, "unit": unit,
                            "higher_is_better": False})  # fmt: skip
        print(json.dumps({"bench": "update", "rows": out}))
        return 0
    print("%-62s %12s %12s %7s" % ("case", "obsw", "reference", "ratio"))
    for case, ours, ref, unit in rows:
        print("%-62s %11.4g%s %11.4g%s %7.3f" % (case, ours, unit, ref, unit, ours / ref))
    print("reference: the full package for its size, else the trial's deadline (%g s); "
          "upload %.1f MB/s; package built in %.2f s" % (
              DEADLINE, m["full_bytes"] / m["upload_s"] / 1e6, m["build_s"]))  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
