"""A live OBC for the brick reproductions: `obsw obc serve` of a copy of the sample with the
PUS process and the CFDP entity, on a port base whose every port is free, with its own state
folder; the ground reaches it through the real `obsw` command. Used by the brick tests and by
``tools/brick_campaign.py``."""

import json
import os
import shutil
import signal
import subprocess
import sys
import threading
import time

from obsw_host import sample
from obsw_host.mission.new import free_fleet_base

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))  # a checkout
OBSW = [sys.executable, "-m", "obsw_host.cli"]
BOUND = 60.0  # seconds any one wait of these runs may take, at most


def env_of(mission, base):
    env = dict(
        os.environ,
        PYTHONPATH=os.pathsep.join(
            [os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]
        ),
        PYTHONUNBUFFERED="1",
        OBSW_MISSION=mission,
        OBSW_PORT_BASE=str(base),
    )
    return env


def wait_for(predicate, timeout=BOUND, step=0.05):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        v = predicate()
        if v:
            return v
        time.sleep(step)
    return predicate()


def make_mission(folder, processes=("pus", "cfdp")):
    """A copy of the sample in ``folder`` with only ``processes``; returns its path."""
    shutil.copytree(os.path.dirname(sample.MISSION_PATH), folder)
    path = os.path.join(folder, "mission.json")
    with open(path) as f:
        doc = json.load(f)
    doc["processes"] = {"obc": list(processes)}
    doc.pop("frames", None)
    doc.pop("spacecan", None)
    with open(path, "w") as f:
        json.dump(doc, f, indent=2)
    return folder


class LiveObc:
    """`obsw obc serve` of ``mission`` with state folder ``state``; its output collected."""

    def __init__(self, mission, state, base=None):
        self.mission = mission
        self.state = state
        self.base = base if base is not None else free_fleet_base(1)
        self.env = env_of(mission, self.base)
        self.proc = None
        self.lines = []

    @property
    def files(self):
        return os.path.join(self.state, "files")

    def start(self, wait=True):
        self.proc = subprocess.Popen(
            OBSW + ["obc", "serve", self.mission, "--state", self.state], env=self.env,
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, start_new_session=True,
        )  # fmt: skip
        threading.Thread(target=self._read, args=(self.proc,), daemon=True).start()
        if wait:
            assert self.wait_up(), self.text()
        return self

    def _read(self, proc):
        for line in proc.stdout:
            self.lines.append(line.decode(errors="replace"))

    def wait_up(self):
        n = len(self.lines)
        return wait_for(lambda: any(" up: " in x for x in self.lines[n - 1 :] if x)
                        or self.ping(), BOUND)  # fmt: skip

    def ping(self):
        if self.proc is None or self.proc.poll() is not None:
            return False
        return self.obsw("ground", "--timeout", "0.5", "ping").returncode == 0

    def obsw(self, *args, timeout=BOUND, cwd=None):
        return subprocess.run(OBSW + [str(a) for a in args], env=self.env, capture_output=True,
                              text=True, timeout=timeout, cwd=cwd)  # fmt: skip

    def power_cut(self):
        """kill -9 of the OBC's whole process group: no handler runs."""
        try:
            os.killpg(self.proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        self.proc.wait(BOUND)

    def stop(self):
        if self.proc is None:
            return
        try:
            os.killpg(self.proc.pid, signal.SIGTERM)
        except ProcessLookupError:
            pass
        try:
            self.proc.wait(BOUND)
        except subprocess.TimeoutExpired:
            self.power_cut()

    def restart(self):
        self.stop()
        return self.start()

    def text(self):
        return "".join(self.lines[-60:])

    def said(self, fragment):
        return any(fragment in x for x in self.lines)
