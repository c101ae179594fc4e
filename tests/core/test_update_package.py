"""Update packages: the format read back, and every check that refuses a package."""

import hashlib
import io
import json
import unittest

from obsw.update.package import (
    REASONS,
    BadMagic,
    BadManifest,
    BadPath,
    BadSignature,
    HashMismatch,
    PackageError,
    Reader,
    Truncated,
    WrongMission,
    WrongTarget,
    canonical,
    check_path,
    header,
    sha256_hex,
)

KEY = b"k" * 32


def sign(key, message):
    """A stand-in signature (the reader takes any verifier): SHA-256 of key and message."""
    digest = hashlib.sha256(key + message).digest()
    return digest + digest


def verify(key, signature, message):
    return signature == sign(key, message)


FILES = [("lib/obsw/a.py", b"print('a')\n"), ("mission/mission.json", b"{}" * 700)]


def manifest(files=FILES, base=None, tree=None, **changes):
    m = {
        "format": 1,
        "mission": "sat-1",
        "target": "obc",
        "version": "1.1",
        "base": base,
        "created": "2026-11-25T00:00:00Z",
        "files": [{"path": p, "size": len(d), "sha256": sha256_hex(d)} for p, d in files],
        "tree": tree if tree is not None else dict((p, sha256_hex(d)) for p, d in files),
    }
    m.update(changes)
    return m


def package(m=None, files=FILES, key=KEY):
    body = canonical(m or manifest())
    return header(body, sign(key, body)) + b"".join(d for _, d in files)


def read(data, mission="sat-1", target="obc"):
    reader = Reader(io.BytesIO(data), verify, KEY, mission, target)
    got = {}

    def write(path, chunk):
        if chunk is not None:
            got[path] = got.get(path, b"") + chunk
        else:
            got.setdefault(path, b"")

    reader.files(write)
    return reader.manifest, got


class TestRoundTrip(unittest.TestCase):
    def test_every_file_comes_out_whole(self):
        m, got = read(package())
        self.assertEqual(m["version"], "1.1")
        self.assertEqual(got, dict(FILES))

    def test_an_empty_file(self):
        files = [("lib/empty.py", b"")]
        m, got = read(package(manifest(files), files))
        self.assertEqual(got, {"lib/empty.py": b""})

    def test_the_manifest_is_canonical(self):
        body = canonical({"b": 1, "a": [1, 2]})
        self.assertEqual(body, b'{"a":[1,2],"b":1}')
        self.assertEqual(json.loads(body), {"a": [1, 2], "b": 1})

    def test_a_delta_carries_part_of_its_tree(self):
        tree = dict((p, sha256_hex(d)) for p, d in FILES)
        tree["lib/obsw/other.py"] = sha256_hex(b"x")
        m, got = read(package(manifest(base="1.0", tree=tree)))
        self.assertEqual(m["base"], "1.0")
        self.assertEqual(sorted(got), sorted(p for p, _ in FILES))


class TestRefused(unittest.TestCase):
    def assert_refused(self, cls, data, **where):
        with self.assertRaises(cls) as cm:
            read(data, **where)
        self.assertTrue(isinstance(cm.exception, PackageError))
        self.assertIn(cm.exception.code, REASONS)

    def test_not_a_package(self):
        self.assert_refused(BadMagic, b"PK\x03\x04" + b"\x00" * 40)

    def test_cut_anywhere(self):
        data = package()
        for n in (0, 5, 8, 12, 100, len(data) - 1):
            with self.assertRaises(PackageError):
                read(data[:n])
        self.assert_refused(Truncated, data[:-1])

    def test_one_changed_byte_in_a_file(self):
        data = bytearray(package())
        data[-3] ^= 0x01
        self.assert_refused(HashMismatch, bytes(data))

    def test_one_changed_byte_in_the_manifest(self):
        data = bytearray(package())
        data[20] ^= 0x01
        self.assert_refused(BadSignature, bytes(data))

    def test_another_key(self):
        self.assert_refused(BadSignature, package(key=b"x" * 32))

    def test_another_mission(self):
        self.assert_refused(WrongMission, package(), mission="sat-2")

    def test_another_target(self):
        self.assert_refused(WrongTarget, package(), target="reconfig")

    def test_bytes_after_the_last_file(self):
        self.assert_refused(BadManifest, package() + b"x")

    def test_a_full_package_without_a_file_of_its_tree(self):
        tree = dict((p, sha256_hex(d)) for p, d in FILES)
        tree["lib/obsw/missing.py"] = sha256_hex(b"")
        self.assert_refused(BadManifest, package(manifest(tree=tree)))

    def test_a_file_whose_hash_is_not_its_tree_entry(self):
        tree = dict((p, sha256_hex(b"other")) for p, _ in FILES)
        self.assert_refused(BadManifest, package(manifest(tree=tree)))

    def test_fields_missing(self):
        for change in ({"format": 2}, {"version": ""}, {"mission": None}, {"base": 3}):
            self.assert_refused(BadManifest, package(manifest(**change)))

    def test_paths_that_leave_the_slot(self):
        for path in ("../x.py", "/etc/passwd", "lib/../../x", "a//b", "./a", "a\\b", ""):
            files = [(path, b"x")]
            with self.assertRaises(BadPath):
                check_path(path)
            self.assert_refused(BadPath, package(manifest(files), files))

    def test_a_good_path(self):
        self.assertEqual(check_path("lib/obsw/update/package.py"), "lib/obsw/update/package.py")

    def test_a_signature_of_the_wrong_size_cannot_be_written(self):
        with self.assertRaises(ValueError):
            header(b"{}", b"short")


if __name__ == "__main__":
    unittest.main()
