"""Update package edges: version order (numbers, not text; a suffix before the release), the
rollback floor and the signed downgrade, a manifest with one of files/tree wrong, a manifest of
1 MiB read and one octet more refused, and files handed out in chunks of at most 1 KiB."""

import io
import struct
import unittest

from obsw.update.package import (
    MAGIC,
    BadManifest,
    BadPath,
    BadSignature,
    Reader,
    Rollback,
    canonical,
    check_floor,
    check_manifest,
    check_path,
    header,
    sha256_hex,
    version_key,
)
from test_update_package import KEY, manifest, sign, verify


class TestVersionOrder(unittest.TestCase):
    def test_numbers_not_text(self):
        self.assertTrue(version_key("1.10") > version_key("1.9"))
        self.assertTrue(version_key("10") > version_key("9"))
        self.assertTrue(version_key("2") > version_key("1.99"))

    def test_a_suffix_comes_before_its_release(self):
        self.assertTrue(version_key("1.9") > version_key("1.9rc1"))
        self.assertTrue(version_key("1.9rc1") > version_key("1.8"))

    def test_equal_versions_and_odd_parts(self):
        self.assertEqual(version_key("1.2"), version_key("1.2"))
        self.assertEqual(version_key("0"), ((0, 1, ""),))
        self.assertEqual(version_key("rc"), ((-1, 0, "rc"),))
        self.assertEqual(version_key("1."), ((1, 1, ""), (-1, 1, "")))


class TestFloor(unittest.TestCase):
    def test_at_the_floor_and_above(self):
        for v in ("2.0", "2.0.1", "2.1", "10.0"):
            m = {"version": v}
            self.assertIs(check_floor(m, "2.0"), m)

    def test_below_the_floor(self):
        for v in ("1.9", "1.99", "2.0rc1"):
            with self.assertRaises(Rollback):
                check_floor({"version": v}, "2.0")

    def test_a_signed_downgrade_passes_the_floor(self):
        m = {"version": "1.0", "downgrade": True}
        self.assertIs(check_floor(m, "2.0"), m)
        with self.assertRaises(Rollback):
            check_floor({"version": "1.0", "downgrade": False}, "2.0")

    def test_no_floor(self):
        m = {"version": "A"}
        self.assertIs(check_floor(m, None), m)


class TestManifestShape(unittest.TestCase):
    def test_files_and_tree_each_of_the_right_kind(self):
        good = manifest()
        self.assertIs(check_manifest(good), good)
        for key, value in (("tree", []), ("files", {}), ("tree", None), ("files", None)):
            m = manifest()
            m[key] = value
            with self.assertRaises(BadManifest):
                check_manifest(m)


class TestManifestLength(unittest.TestCase):
    def test_a_manifest_of_one_mib_at_most(self):
        limit = 1 << 20
        for n, error in ((limit, BadSignature), (limit + 1, BadManifest)):  # read, or refused
            data = MAGIC + struct.pack(">I", n) + bytes(n) + bytes(64)
            with self.assertRaises(error) as cm:
                Reader(io.BytesIO(data), verify, KEY, "sat-1", "obc")
            self.assertIs(type(cm.exception), error)
        self.assertIn("manifest of 1048577 bytes: more than 1048576", str(cm.exception))


class TestChunks(unittest.TestCase):
    def test_a_file_comes_in_chunks_of_at_most_1_kib(self):
        data = bytes(range(256)) * 8 + b"x"  # 2049 octets
        files = [("lib/big.bin", data)]
        m = manifest(files)
        body = canonical(m)
        reader = Reader(
            io.BytesIO(header(body, sign(KEY, body)) + data), verify, KEY, "sat-1", "obc"
        )
        sizes = []
        reader.files(lambda path, chunk: chunk is not None and sizes.append(len(chunk)))
        self.assertEqual(sizes, [1024, 1024, 1])
        self.assertEqual(m["files"][0]["sha256"], sha256_hex(data))


if __name__ == "__main__":
    unittest.main()


class TestPaths(unittest.TestCase):
    def test_one_character_paths(self):
        self.assertEqual(check_path("a"), "a")
        for bad in ("/", ".", "\\\\"):
            with self.assertRaises(BadPath):
                check_path(bad)

    def test_an_absolute_path_is_named_as_such(self):
        for bad in ("/etc/passwd", "/a"):
            with self.assertRaises(BadPath) as cm:
                check_path(bad)
            self.assertIn("not a relative POSIX path", str(cm.exception))
        with self.assertRaises(BadPath) as cm:
            check_path("lib/")
        self.assertIn("empty, '.' or '..' part", str(cm.exception))


class TestTreeDigests(unittest.TestCase):
    def test_64_hex_digits_and_nothing_else(self):
        for digest in ("ab" * 31 + "a", "ab" * 32 + "a", 5, None):
            m = manifest()
            m["tree"] = dict(m["tree"], extra=digest)
            with self.assertRaises(BadManifest):
                check_manifest(m)


class TestSignedButNotJson(unittest.TestCase):
    def test_a_signed_manifest_that_is_not_json(self):
        for body in (b"{not json", b"\xff\xfe", b"[" * 20 + b"]" * 20):
            data = header(body, sign(KEY, body))
            with self.assertRaises(BadManifest):
                Reader(io.BytesIO(data), verify, KEY, "sat-1", "obc")
