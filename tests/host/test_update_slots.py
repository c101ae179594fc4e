"""The OBC's software slots: staging refuses every bad package, a trial is confirmed or rolled
back, and a power cut at any step of staging and activation leaves a bootable, known version."""

import hashlib
import json
import os
import shutil

import pytest
from obsw.update.package import (
    BadManifest,
    BadSignature,
    HashMismatch,
    WrongMission,
)
from obsw.update.signature import verify
from obsw_host.update import build as b
from obsw_host.update.slots import FACTORY, Software, UpdateRefused

MISSION = "sat-1"


@pytest.fixture(scope="module")
def key():
    from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

    return Ed25519PrivateKey.generate()


@pytest.fixture(scope="module")
def public(key):
    return bytes.fromhex(b.public_hex(key))


def make_tree(root, files):
    out = {}
    for path, data in files.items():
        target = os.path.join(root, *path.split("/"))
        os.makedirs(os.path.dirname(target), exist_ok=True)
        with open(target, "wb") as f:
            f.write(data)
        out[path] = target
    return out


V1 = {"lib/obsw_host/x.py": b"X = 1\n", "lib/obsw/y.py": b"Y = 1\n", "mission/mission.json": b"{}"}
V2 = dict(V1, **{"lib/obsw_host/x.py": b"X = 2\n", "lib/obsw_host/new.py": b"N = 2\n"})


def package(tmp, key, version, files, base=None, mission=MISSION, name=None):
    src = make_tree(os.path.join(tmp, "src-" + version), files)
    out = os.path.join(tmp, name or "%s.obsw" % version)
    b.build(out, src, mission=mission, version=version, key=key, base=base)
    return out


def software(tmp):
    return Software(os.path.join(tmp, "state", "software"), "0.1.0", os.path.join(tmp, "m"))


def stage(sw, path, public):
    return sw.stage(path, verify, public, MISSION)


def slot_files(sw, slot):
    root = sw.slot_dir(slot)
    out = {}
    for d, _, names in os.walk(root):
        for n in names:
            p = os.path.join(d, n)
            out[os.path.relpath(p, root).replace(os.sep, "/")] = open(p, "rb").read()
    return out


def bootable(sw, slot):
    """The slot's files are the ones its manifest's tree names (what the self-test checks)."""
    if slot == FACTORY:
        return True
    m = sw.manifest(slot)
    if m is None:
        return False
    files = slot_files(sw, slot)
    return all(
        path in files and hashlib.sha256(files[path]).hexdigest() == digest
        for path, digest in m["tree"].items()
    )


def test_stage_activate_confirm(tmp_path, key, public):
    sw = software(str(tmp_path))
    assert sw.choose(3) == (FACTORY, False)
    m = stage(sw, package(str(tmp_path), key, "1.1", V1), public)
    assert m["version"] == "1.1" and sw.read()["staged"] == "a"
    assert slot_files(sw, "a")["lib/obsw_host/x.py"] == b"X = 1\n"
    assert sw.activate() == "1.1"
    assert sw.choose(3) == ("a", True)
    assert sw.code("a")[0] == os.path.join(sw.root, "a", "lib")
    assert sw.confirm() == "a"
    assert sw.choose(3) == ("a", False)
    record = sw.read()
    assert (record["active"], record["previous"]) == ("a", FACTORY)
    assert [e["event"] for e in record["log"]] == ["staged", "activated", "confirmed"]


def test_a_delta_is_built_from_the_running_version(tmp_path, key, public):
    tmp = str(tmp_path)
    sw = software(tmp)
    v1 = package(tmp, key, "1.1", V1)
    base = b.base_manifest(v1, public, MISSION, "obc")
    stage(sw, v1, public)
    sw.activate(), sw.choose(3), sw.confirm()
    delta = package(tmp, key, "1.2", V2, base=base)
    with open(delta, "rb") as f:
        assert b"Y = 1" not in f.read()  # unchanged files stay on the ground
    m = stage(sw, delta, public)
    assert m["base"] == "1.1" and len(m["files"]) == 2
    assert slot_files(sw, "b")["lib/obsw/y.py"] == b"Y = 1\n"  # from slot a
    assert bootable(sw, "b")


def test_a_delta_to_another_version_is_refused(tmp_path, key, public):
    tmp = str(tmp_path)
    sw = software(tmp)
    v1 = package(tmp, key, "1.1", V1)
    delta = package(tmp, key, "1.2", V2, base=b.base_manifest(v1, public, MISSION, "obc"))
    with pytest.raises(BadManifest, match="delta to version 1.1, the OBC runs 0.1.0"):
        stage(sw, delta, public)


@pytest.mark.parametrize("spoil", ["byte", "signature", "mission", "truncated"])
def test_a_bad_package_is_refused_and_removed(tmp_path, key, public, spoil):
    from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

    tmp = str(tmp_path)
    sw = software(tmp)
    signer = Ed25519PrivateKey.generate() if spoil == "signature" else key
    mission = "sat-2" if spoil == "mission" else MISSION
    path = package(tmp, signer, "1.1", V1, mission=mission)
    data = bytearray(open(path, "rb").read())
    if spoil == "byte":
        data[-2] ^= 0x20  # in the last file
    if spoil == "truncated":
        data = data[:-1]
    with open(path, "wb") as f:
        f.write(data)
    expected = {"byte": HashMismatch, "signature": BadSignature, "mission": WrongMission}
    with pytest.raises(expected.get(spoil, Exception)) as e:
        stage(sw, path, public)
    assert e.value.code in ("hash_mismatch", "bad_signature", "wrong_mission", "truncated")
    assert not os.path.exists(path)  # never kept, never installed
    assert not os.path.exists(sw.slot_dir("a")) and not os.path.exists(sw.slot_dir("a") + ".part")
    record = sw.read()
    assert record["staged"] is None
    assert record["log"][-1]["event"] == "refused" and e.value.code in record["log"][-1]["reason"]


def test_a_trial_that_never_comes_up_falls_back(tmp_path, key, public):
    sw = software(str(tmp_path))
    stage(sw, package(str(tmp_path), key, "1.1", V1), public)
    sw.activate()
    assert [sw.choose(2) for _ in range(3)] == [("a", True), ("a", True), (FACTORY, False)]
    entry = sw.read()["log"][-1]
    assert (entry["event"], entry["reason"]) == ("rolled_back", "did not come up in 2 starts")


def test_rollback_by_the_ground(tmp_path, key, public):
    tmp = str(tmp_path)
    sw = software(tmp)
    with pytest.raises(UpdateRefused, match="no previous version"):
        sw.rollback()
    with pytest.raises(UpdateRefused, match="no staged version"):
        sw.activate()
    stage(sw, package(tmp, key, "1.1", V1), public)
    sw.activate()
    with pytest.raises(UpdateRefused, match="on trial"):
        stage(sw, package(tmp, key, "1.2", V2), public)
    sw.choose(3), sw.confirm()
    assert sw.rollback() == FACTORY  # back to the factory version
    assert sw.choose(3) == (FACTORY, False)
    assert sw.rollback() == "a"  # and forward again
    assert sw.choose(3) == ("a", False)


def test_a_failed_trial_keeps_the_version_before(tmp_path, key, public):
    tmp = str(tmp_path)
    sw = software(tmp)
    stage(sw, package(tmp, key, "1.1", V1), public)
    sw.activate(), sw.choose(3), sw.confirm()
    stage(sw, package(tmp, key, "1.2", V2), public)
    sw.activate()
    assert sw.choose(3) == ("b", True)
    sw.fail_trial("not healthy within 60s")
    assert sw.choose(3) == ("a", False)
    assert sw.version("a") == "1.1"


def test_events_are_reported_once(tmp_path, key, public):
    sw = software(str(tmp_path))
    stage(sw, package(str(tmp_path), key, "1.1", V1), public)
    new, done = sw.unreported()
    assert [e["event"] for e in new] == ["staged"]
    done()
    assert sw.unreported()[0] == []
    sw.activate()
    assert [e["event"] for e in sw.unreported()[0]] == ["activated"]


# ------------------------------------------------------------------------ power cuts


class PowerCut(BaseException):
    """The power goes: nothing after it runs (not an Exception: no handler catches it)."""


class Cutter:
    """Counts the operations that change the disk; the ``at``-th one is cut in the middle."""

    def __init__(self, monkeypatch, at=None):
        self.n = 0
        self.at = at
        real_replace, real_rename, real_rmtree = os.replace, os.rename, shutil.rmtree
        real_fsync = os.fsync

        def op(name, real):
            def f(*args, **kwargs):
                self.n += 1
                if self.n == self.at:
                    if name == "rmtree":  # half of the tree is gone
                        for d, _, files in os.walk(args[0]):
                            for x in files[: len(files) // 2 + 1]:
                                os.remove(os.path.join(d, x))
                            break
                    raise PowerCut(name)
                return real(*args, **kwargs)

            return f

        monkeypatch.setattr(os, "replace", op("replace", real_replace))
        monkeypatch.setattr(os, "rename", op("rename", real_rename))
        monkeypatch.setattr(os, "fsync", op("fsync", real_fsync))
        monkeypatch.setattr(shutil, "rmtree", op("rmtree", real_rmtree))


def campaign(tmp, key, public, packages):
    """Every step of two updates: 1.1 staged, activated, started, confirmed; 1.2 staged,
    activated, started and rolled back; then a start."""
    sw = software(tmp)
    stage(sw, packages[0], public)
    sw.activate()
    sw.choose(3)
    sw.confirm()
    stage(sw, packages[1], public)
    sw.activate()
    sw.choose(3)
    sw.fail_trial("self-test failed")
    return sw.choose(3)


def test_a_power_cut_at_every_step_leaves_a_bootable_known_version(tmp_path, key, public):
    def packages(d):
        os.makedirs(d)
        return [package(d, key, "1.1", V1), package(d, key, "1.2", V2)]

    whole = packages(str(tmp_path / "p0"))
    with pytest.MonkeyPatch.context() as mp:
        counter = Cutter(mp)
        assert campaign(str(tmp_path / "whole"), key, public, whole) == ("a", False)
        total = counter.n
    assert total > 20
    outcomes = set()
    for at in range(1, total + 1):
        tmp = str(tmp_path / ("cut%d" % at))
        pkgs = packages(tmp + "-p")
        with pytest.MonkeyPatch.context() as mp:
            Cutter(mp, at)
            with pytest.raises(PowerCut):
                campaign(tmp, key, public, pkgs)
        # power comes back: the next start reads the record from the disk
        sw = software(tmp)
        slot, trial = sw.choose(3)
        assert sw.version(slot) in ("0.1.0", "1.1", "1.2"), at
        assert bootable(sw, slot), (at, slot)
        record = sw.read()
        assert record["staged"] is None or bootable(sw, record["staged"]), at
        json.dumps(record)
        outcomes.add((sw.version(slot), trial))
        # and the update can be taken again from there
        for path in pkgs:
            if not os.path.exists(path):
                continue
            try:
                stage(sw, path, public)
            except (UpdateRefused, BadManifest):
                pass  # on trial, or a delta to what no longer runs
    assert {v for v, _ in outcomes} >= {"0.1.0", "1.1", "1.2"}


def test_a_package_carries_no_state_and_no_pipe_of_a_running_obc(tmp_path):
    mission = tmp_path / "m"
    (mission / "procedures").mkdir(parents=True)
    (mission / "mission.json").write_text("{}")
    (mission / "procedures" / "p.pluto").write_text("procedure p end procedure")
    (mission / "state" / "software").mkdir(parents=True)
    (mission / "state" / "software" / "record.json").write_text("{}")
    os.mkfifo(str(mission / "procedures" / "engine.pipe"))  # not a file to carry (as a socket)
    files = b.sources(str(mission))
    carried = sorted(p for p in files if p.startswith("mission/"))
    assert carried == ["mission/mission.json", "mission/procedures/p.pluto"]
    assert any(p.startswith("lib/obsw/") for p in files)
