"""In-flight updates of a running OBC (`obsw obc serve`) with the ground's `obsw update`: a good
version is uploaded by CFDP, staged, activated and runs (its own code and mission); one that
crashes at start and one that hangs are rolled back by the platform manager within the
deadline; bad packages are refused and reported; a power cut during a trial leaves the OBC
starting again on a known version. Every wait has a deadline; nothing asserts on time."""

import json
import os
import shutil
import signal
import subprocess
import sys

import pytest
from obsw_host import sample
from obsw_host.mission.ids import MissionIds
from obsw_host.pus.ground import Ground, PusTimeout
from obsw_host.update import build as b
from test_obc_assembly import wait_for

BIN = os.path.dirname(sys.executable)
DEADLINE = 10.0  # the trial's deadline in these missions


def ports_base():
    return 21000 + (os.getpid() % 500) * 40


@pytest.fixture
def mission(tmp_path):
    """The sample in its own folder, with an update key and small deadlines; (folder, key)."""
    folder = tmp_path / "sat"
    shutil.copytree(os.path.dirname(sample.MISSION_PATH), folder)
    b.keygen(str(tmp_path / "update.key"), allow_git=True)
    shutil.copy(tmp_path / "update.key.pub", folder / "update.pub")
    edit(folder, lambda doc: doc.update(
        ports={"base": ports_base()},
        update={"public_key": "update.pub", "deadline": DEADLINE, "healthy_after": 1.0},
    ))  # fmt: skip
    return str(folder), b.load_private(str(tmp_path / "update.key"))


def edit(folder, change):
    path = os.path.join(folder, "mission.json")
    with open(path) as f:
        doc = json.load(f)
    change(doc)
    with open(path, "w") as f:
        json.dump(doc, f, indent=2)


def package(tmp_path, mission, key, version, replace=None, mission_change=None):
    """A package of this software and ``mission`` (a copy changed by ``mission_change``), with
    ``replace`` ({package path: text}) instead of or besides its files."""
    folder = str(tmp_path / ("m-" + version))
    shutil.copytree(mission, folder)
    if mission_change:
        edit(folder, mission_change)
    files = b.sources(folder)
    for path, text in (replace or {}).items():
        src = str(tmp_path / ("%s-%s" % (version, path.replace("/", "_"))))
        with open(src, "w") as f:
            f.write(text)
        files[path] = src
    out = str(tmp_path / ("v%s.obsw" % version))
    b.build(out, files, mission="sample-spacecraft", version=version, key=key)
    return out


def obsw(*args, mission):
    env = dict(os.environ, OBSW_MISSION=mission)
    return subprocess.run([os.path.join(BIN, "obsw"), *args], env=env, capture_output=True,
                          text=True, timeout=180)  # fmt: skip


class Obc:
    def __init__(self, mission, state):
        self.mission = mission
        self.state = state
        self.log = os.path.join(os.path.dirname(state), "obc.log")
        self.proc = None
        ids = MissionIds.locate(mission)
        self.ground = Ground(ids.sdb, target=("127.0.0.1", ids.ports.pus), timeout=1.0)
        self.ground.keep_unsolicited = 100000
        # every TM to this ground, as down a link, also when it sent no TC to a new process
        tm_to = "127.0.0.1:%d" % self.ground.sock.getsockname()[1]
        edit(mission, lambda doc: doc["pus"].update(tm_to=tm_to))

    def start(self):
        out = open(self.log, "a")
        self.proc = subprocess.Popen(
            [os.path.join(BIN, "obsw"), "obc", "serve", self.mission, "--state", self.state],
            stdout=out, stderr=subprocess.STDOUT, start_new_session=True)  # fmt: skip
        assert wait_for(self.answers, 60), self.text()
        return self

    def answers(self):
        try:
            return self.ground.ping(timeout=0.5).ok
        except Exception:
            return False

    def power_cut(self):
        os.killpg(self.proc.pid, signal.SIGKILL)
        self.proc.wait(10)

    def stop(self):
        if self.proc is not None and self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(20)
            except subprocess.TimeoutExpired:
                self.power_cut()
        self.ground.close()

    def text(self):
        with open(self.log) as f:
            return f.read()[-3000:]

    def record(self):
        with open(os.path.join(self.state, "software", "boot.json")) as f:
            return json.load(f)

    def status(self):
        try:
            tx = self.ground.get_parameters("Software.version", "Software.slot")
        except PusTimeout:
            return {}
        return tx.reply["values"] if tx.ok and tx.reply else {}

    def events(self, name):
        """The data of every ``name`` event received so far."""
        self.answers()  # drive the socket: TM that came meanwhile
        return [d["data"] for tm, d in self.ground.received
                if tm.service == 5 and isinstance(d, dict) and d.get("event") == name]  # fmt: skip

    def runs(self, version, slot):
        return self.status() == {"Software.version": version, "Software.slot": slot}


@pytest.fixture
def obc(mission, tmp_path):
    o = Obc(mission[0], str(tmp_path / "state"))
    yield o
    o.stop()


def push(path, mission):
    r = obsw("update", "push", path, mission=mission)
    return r.returncode, r.stdout + r.stderr


def test_a_good_version_runs_and_a_crashing_one_is_rolled_back(tmp_path, mission, obc):
    folder, key = mission
    obc.start()
    assert obc.runs("0.1.0", "factory")
    # 1.1 brings a module of its own, and a mission whose self-test needs it: it passes only
    # when the processes run 1.1's code with 1.1's mission
    good = package(tmp_path, folder, key, "1.1",
                   replace={"lib/obsw_host/update_check.py": "def check():\n    return True\n"},
                   mission_change=lambda d: d["update"].update(
                       self_test="obsw_host.update_check:check"))  # fmt: skip
    code, said = push(good, folder)
    assert code == 0, said
    assert "delivered" in said and "completion success" in said
    assert obsw("update", "activate", mission=folder).returncode == 0
    assert wait_for(lambda: obc.runs("1.1", "a"), 60), obc.text()
    assert wait_for(lambda: obc.record()["active"] == "a", 30), obc.text()
    assert wait_for(lambda: obc.events("Software.confirmed"), 10)
    hk = obc.ground.housekeeping(20).reply["values"]  # the sample's software structure
    assert (hk["Software.version"], hk["Software.slot"]) == ("1.1", "a"), hk
    # 1.2 crashes as soon as a process starts
    broken = {"lib/obsw_host/obc/assembly.py": "raise RuntimeError('1.2 is broken')\n"}
    bad = package(tmp_path, folder, key, "1.2", replace=broken)
    assert push(bad, folder)[0] == 0
    assert obsw("update", "activate", mission=folder).returncode == 0
    assert wait_for(lambda: obc.record()["log"][-1]["event"] == "rolled_back", 90), obc.text()
    assert "process obc" in obc.record()["log"][-1]["reason"]
    assert wait_for(lambda: obc.runs("1.1", "a"), 60), obc.text()
    rolled = wait_for(lambda: obc.events("Software.rolled_back"), 10)
    assert rolled and rolled[-1]["version"] == "1.2", rolled
    # the ground goes back to the factory version, and forward again
    assert obsw("update", "rollback", mission=folder).returncode == 0
    assert wait_for(lambda: obc.runs("0.1.0", "factory"), 60), obc.text()
    assert obsw("update", "rollback", mission=folder).returncode == 0
    assert wait_for(lambda: obc.runs("1.1", "a"), 60), obc.text()


def test_a_hanging_version_is_rolled_back_at_the_deadline(tmp_path, mission, obc):
    folder, key = mission
    obc.start()
    hang = {"lib/obsw_host/obc/assembly.py": "import time\ntime.sleep(3600)\n"}
    hangs = package(tmp_path, folder, key, "1.1", replace=hang)
    assert push(hangs, folder)[0] == 0
    assert obsw("update", "activate", mission=folder).returncode == 0
    assert wait_for(lambda: obc.record()["log"][-1]["event"] == "rolled_back", 90), obc.text()
    assert obc.record()["log"][-1]["reason"] == "not healthy within %gs" % DEADLINE
    assert wait_for(lambda: obc.runs("0.1.0", "factory"), 60), obc.text()


def test_bad_packages_are_refused_and_reported(tmp_path, mission, obc):
    folder, key = mission
    obc.start()
    good = package(tmp_path, folder, key, "1.1")
    spoiled = str(tmp_path / "spoiled.obsw")
    data = bytearray(open(good, "rb").read())
    data[-10] ^= 0x01
    with open(spoiled, "wb") as f:
        f.write(data)
    code, said = push(spoiled, folder)
    assert code == 1 and "HASH_MISMATCH" in said, said
    from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

    forged = package(tmp_path, folder, Ed25519PrivateKey.generate(), "1.2")
    code, said = push(forged, folder)
    assert code == 1 and "BAD_SIGNATURE" in said, said
    refused = wait_for(lambda: len(obc.events("Software.refused")) >= 2 and obc.events(
        "Software.refused"), 10)  # fmt: skip
    assert [r["reason"].split(":")[0] for r in refused] == ["hash_mismatch", "bad_signature"]
    assert not os.listdir(os.path.join(obc.state, "files", "update"))  # removed, not kept
    assert obc.record()["staged"] is None and obc.runs("0.1.0", "factory")
    code, said = push(good, folder)
    assert code == 0, said


def test_a_power_cut_during_the_trial(tmp_path, mission, obc):
    folder, key = mission
    # a trial long enough to cut, with a deadline far beyond it: a loaded machine's slow
    # start must not roll the version back (the rollback at the deadline has its own test)
    edit(folder, lambda d: d["update"].update(healthy_after=8.0, deadline=60.0))
    obc.start()
    good = package(tmp_path, folder, key, "1.1")
    assert push(good, folder)[0] == 0
    assert obsw("update", "activate", mission=folder).returncode == 0
    assert wait_for(lambda: obc.record()["trial"] and obc.runs("1.1", "a"), 60), obc.text()
    obc.power_cut()  # in the trial: 1.1 runs, not confirmed yet
    assert obc.record()["trial"] == {"slot": "a", "starts": 1}, obc.text()
    obc.start()  # the trial goes on: its second start
    assert obc.runs("1.1", "a")
    assert wait_for(lambda: obc.record()["active"] == "a", 60), obc.text()
    obc.power_cut()
    obc.start()
    assert obc.runs("1.1", "a") and obc.record()["trial"] is None


def test_the_functions_events_and_parameters_are_in_yamcs_database(tmp_path):
    """An operator of Yamcs has the update's commands, events and parameters by name (the
    generated XTCE of the sample)."""
    from obsw_host.yamcs import database
    from obsw_host.yamcs.xtce import generate

    xml = generate(database.load(sample.SDB_PATH))
    for name in ("stage", "activate", "rollback", "staged", "refused", "rolled_back",
                 "version", "slot", "pending", "trial_starts"):  # fmt: skip
        assert 'name="%s' % name in xml, name
