"""Anti-rollback and whole-package checks (issue 34): the OBC keeps a version floor (the newest
version it confirmed, never below the factory's) and refuses an older signed package unless
its signed manifest allows the downgrade; `obsw update show` checks every file, not only the
signature; `Software.stage` takes packages from the update folder only and leaves every other
file of the filestore alone."""

import os

import pytest
from obsw.il.errors import ComponentError
from obsw.update.package import Rollback, version_key
from obsw_host.cli import main
from obsw_host.update import build as b
from obsw_host.update.component import INBOX, SoftwareComponent
from test_update_slots import V1, V2, package, software, stage


@pytest.fixture(scope="module")
def key():
    from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

    return Ed25519PrivateKey.generate()


@pytest.fixture(scope="module")
def public(key):
    return bytes.fromhex(b.public_hex(key))


def confirmed(sw, path, public):
    stage(sw, path, public)
    sw.activate()
    sw.choose(3)
    sw.confirm()


@pytest.mark.parametrize(
    "older, newer",
    [("1.1", "1.2"), ("1.9", "1.10"), ("1.9rc1", "1.9"), ("1", "1.0"), ("0.1.0", "0.1.1")],
)
def test_versions_order(older, newer):
    assert version_key(older) < version_key(newer)
    assert not version_key(newer) < version_key(older)
    assert version_key(newer) == version_key(newer)


def test_an_older_package_is_refused_unless_its_manifest_allows_it(tmp_path, key, public):
    tmp = str(tmp_path)
    sw = software(tmp)
    assert sw.floor() == "0.1.0"
    confirmed(sw, package(tmp, key, "1.2", V2), public)
    assert sw.floor() == "1.2"
    old = package(tmp, key, "1.1", V1)
    with pytest.raises(Rollback) as e:
        stage(sw, old, public)
    assert "1.1 is older than 1.2" in str(e.value)
    record = sw.read()
    assert record["staged"] is None
    assert record["log"][-1]["event"] == "refused" and "rollback" in record["log"][-1]["reason"]
    assert not os.path.exists(sw.slot_dir("b") + ".part")
    # the same version again is no rollback; a signed downgrade is taken
    stage(sw, package(tmp, key, "1.2", V2, name="again.obsw"), public)
    src = {p: str(tmp_path / ("d-" + p.replace("/", "_"))) for p in V1}
    for p, f in src.items():
        with open(f, "wb") as out:
            out.write(V1[p])
    down = str(tmp_path / "down.obsw")
    b.build(down, src, mission="sat-1", version="1.0", key=key, downgrade=True)
    assert stage(sw, down, public)["version"] == "1.0"
    confirmed_floor = sw.floor()
    sw.activate()
    sw.choose(3)
    sw.confirm()
    assert sw.floor() == confirmed_floor == "1.2"  # a downgrade never lowers the floor


def test_a_manifest_downgrade_field_must_be_a_boolean():
    from obsw.update.package import BadManifest, check_manifest

    m = {"format": 1, "mission": "m", "target": "obc", "version": "1", "created": "x",
         "base": None, "files": [], "tree": {}, "downgrade": "yes"}  # fmt: skip
    with pytest.raises(BadManifest):
        check_manifest(m)


def test_stage_only_takes_packages_from_the_update_folder(tmp_path, key, public):
    from obsw.update.signature import verify

    tmp = str(tmp_path)
    sw = software(tmp)
    files = tmp_path / "files"
    (files / "memory").mkdir(parents=True)
    image = files / "memory" / "image.bin"
    image.write_bytes(b"\x01" * 100)
    data = files / "data.txt"
    data.write_text("keep me")
    comp = SoftwareComponent(sw, str(files), public, "sat-1", verify)
    for name in ("memory/image.bin", "data.txt", "../state/software/boot.json", INBOX):
        with pytest.raises(ComponentError) as e:
            comp.stage(name)
        assert e.value.code in ("BAD_FILE", "NO_FILE"), name
    assert image.read_bytes() == b"\x01" * 100 and data.read_text() == "keep me"
    os.symlink(str(image), str(files / INBOX / "link.obsw"))
    with pytest.raises(ComponentError):
        comp.stage(INBOX + "/link.obsw")
    assert image.read_bytes() == b"\x01" * 100
    bad = files / INBOX / "bad.obsw"
    bad.write_bytes(b"not a package")
    with pytest.raises(ComponentError) as e:
        comp.stage(INBOX + "/bad.obsw")
    assert e.value.code == "BAD_MAGIC"
    assert not bad.exists()  # a refused package in the update folder is removed


def mission_with_key(tmp_path, key):
    import json
    import shutil

    from obsw_host import sample

    folder = tmp_path / "sat"
    shutil.copytree(os.path.dirname(sample.MISSION_PATH), folder)
    (folder / "update.pub").write_text(b.public_hex(key) + "\n")
    doc = json.loads((folder / "mission.json").read_text())
    doc["update"] = {"public_key": "update.pub"}
    (folder / "mission.json").write_text(json.dumps(doc))
    return str(folder)


def test_update_show_checks_every_file(tmp_path, key, capsys):
    folder = mission_with_key(tmp_path, key)
    pkg = str(tmp_path / "v.obsw")
    src = {p: str(tmp_path / ("s-" + p.replace("/", "_"))) for p in V1}
    for p, f in src.items():
        with open(f, "wb") as out:
            out.write(V1[p])
    b.build(pkg, src, mission="sample-spacecraft", version="1.1", key=key)
    assert main(["update", "show", pkg, "--mission", folder]) == 0
    assert "signature and every file good" in capsys.readouterr().out
    data = open(pkg, "rb").read()
    corrupt = str(tmp_path / "corrupt.obsw")
    with open(corrupt, "wb") as f:
        f.write(data[:-3] + bytes(x ^ 0xFF for x in data[-3:]))
    truncated = str(tmp_path / "truncated.obsw")
    with open(truncated, "wb") as f:
        f.write(data[:-5])
    for bad, code in ((corrupt, "hash_mismatch"), (truncated, "truncated")):
        assert main(["update", "show", bad, "--mission", folder]) != 0
        err = capsys.readouterr().err
        assert code in err, err


def left_behind(sw):
    return sorted(n for n in os.listdir(sw.root) if n not in ("boot.json", "boot.lock"))


def test_a_nul_in_a_path_or_a_deep_manifest_fails_with_a_reason_and_leaves_nothing(
    tmp_path, key, public
):  # noqa: E501
    from obsw.update.package import BadManifest, BadPath, header

    tmp = str(tmp_path)
    sw = software(tmp)
    src = tmp_path / "x.py"
    src.write_bytes(b"X = 1\n")
    nul = str(tmp_path / "nul.obsw")
    b.build(nul, {"lib/obsw_host/x\0.py": str(src)}, mission="sat-1", version="1.1", key=key)
    deep = str(tmp_path / "deep.obsw")
    body = b'{"format":1,"x":' + b"[" * 100000 + b"]" * 100000 + b"}"
    with open(deep, "wb") as f:
        f.write(header(body, key.sign(body)))
    for path, error, code in ((nul, BadPath, "bad_path"), (deep, BadManifest, "bad_manifest")):
        with pytest.raises(error):
            stage(sw, path, public)
        assert left_behind(sw) == []
        assert not os.path.exists(path)
        last = sw.read()["log"][-1]
        assert last["event"] == "refused" and last["reason"].startswith(code), last
