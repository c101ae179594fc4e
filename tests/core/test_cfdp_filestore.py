"""CFDP filestore interface: the in-memory and os-backed filestores, filestore requests."""

import os
import unittest

from obsw.cfdp.defs import FS_NOT_PERFORMED, FS_SUCCESS
from obsw.cfdp.filestore import (
    FilestoreError,
    MemoryFilestore,
    OsFilestore,
    execute_request,
    execute_requests,
    normalize,
)
from obsw.cfdp.tlv import FilestoreRequest


def _tmpdir():
    """A folder of this process in the temp folder ($TMPDIR, else /tmp); tearDown removes it."""
    temp = (os.getenv("TMPDIR") if hasattr(os, "getenv") else None) or "/tmp"
    base = temp.rstrip("/") + "/obsw-cfdp-fs-%d" % (os.getpid() if hasattr(os, "getpid") else 0)
    try:
        os.mkdir(base)
    except OSError:
        pass
    return base


def _rmtree(path):
    try:
        names = os.listdir(path)
    except OSError:
        return
    for n in names:
        p = path + "/" + n
        try:
            os.remove(p)
        except OSError:
            _rmtree(p)
    os.rmdir(path)


class Common:
    def fs(self):
        raise NotImplementedError

    def test_write_read_random_access(self):
        fs = self.fs()
        h = fs.open_write("f.bin")
        h.write(4, b"EFGH")
        h.write(0, b"ABCD")
        h.write(8, b"IJ")
        h.close()
        self.assertEqual(fs.read_bytes("f.bin"), b"ABCDEFGHIJ")
        self.assertEqual(fs.read_bytes("f.bin", 2, 3), b"CDE")
        self.assertEqual(fs.size("f.bin"), 10)

    def test_atomic_write_replaces(self):
        fs = self.fs()
        fs.write_atomic("state", b"one")
        fs.write_atomic("state", b"two")
        self.assertEqual(fs.read_bytes("state"), b"two")
        self.assertFalse(fs.exists("state.new"))

    def test_requests(self):
        fs = self.fs()
        fs.write_bytes("a", b"123")
        fs.write_bytes("b", b"45")
        ok = [
            FilestoreRequest(0, "c"),
            FilestoreRequest(3, "a", "b"),  # append b to a
            FilestoreRequest(2, "c", "d"),
            FilestoreRequest(4, "d", "a"),  # replace d with a
            FilestoreRequest(5, "dir"),
            FilestoreRequest(6, "dir"),
            FilestoreRequest(1, "b"),
            FilestoreRequest(7, "nothing"),
            FilestoreRequest(8, "nodir"),
        ]
        for r in ok:
            self.assertEqual(execute_request(fs, r).status, FS_SUCCESS)
        self.assertEqual(fs.read_bytes("a"), b"12345")
        self.assertEqual(fs.read_bytes("d"), b"12345")
        self.assertFalse(fs.exists("b"))
        self.assertFalse(fs.exists("c"))

    def test_request_failures(self):
        fs = self.fs()
        fs.write_bytes("x", b"")
        self.assertEqual(execute_request(fs, FilestoreRequest(1, "missing")).status, 1)
        self.assertEqual(execute_request(fs, FilestoreRequest(2, "missing", "y")).status, 1)
        self.assertEqual(execute_request(fs, FilestoreRequest(2, "x", "x")).status, 2)
        self.assertEqual(execute_request(fs, FilestoreRequest(3, "missing", "x")).status, 1)
        self.assertEqual(execute_request(fs, FilestoreRequest(4, "x", "missing")).status, 2)
        self.assertEqual(execute_request(fs, FilestoreRequest(6, "nodir")).status, 1)
        resp = execute_requests(fs, [FilestoreRequest(1, "missing"), FilestoreRequest(0, "never")])
        self.assertEqual([r.status for r in resp], [1, FS_NOT_PERFORMED])
        self.assertFalse(fs.exists("never"))

    def test_listdir(self):
        fs = self.fs()
        fs.mkdir("d")
        fs.write_bytes("d/one", b"1")
        fs.write_bytes("d/two", b"22")
        self.assertEqual(fs.listdir("d"), ["one", "two"])
        self.assertTrue(fs.is_dir("d"))
        self.assertFalse(fs.is_dir("d/one"))

    def test_missing_file(self):
        fs = self.fs()
        with self.assertRaises(FilestoreError):
            fs.open_read("nope")
        with self.assertRaises(OSError):
            fs.size("nope")


class TestMemoryFilestore(Common, unittest.TestCase):
    def fs(self):
        return MemoryFilestore()


class TestOsFilestore(Common, unittest.TestCase):
    def setUp(self):
        self.base = _tmpdir()
        self.root = self.base + "/root"
        _rmtree(self.root)
        os.mkdir(self.root)

    def tearDown(self):
        _rmtree(self.base)  # the process's folder too: nothing is left in the temp folder

    def fs(self):
        return OsFilestore(self.root)

    def test_escape_refused(self):
        fs = self.fs()
        with self.assertRaises(FilestoreError):
            fs.open_write("../outside")
        with self.assertRaises(FilestoreError):
            fs.read_bytes("a/../../etc/passwd")
        # a leading slash stays inside the root
        fs.write_bytes("/inside", b"x")
        self.assertTrue(fs.exists("inside"))


class TestNormalize(unittest.TestCase):
    def test_normalize(self):
        self.assertEqual(normalize("/a/./b//c"), "a/b/c")
        self.assertEqual(normalize("a/b/../c"), "a/c")
        self.assertIsNone(normalize("a/../.."))
        self.assertEqual(normalize(""), "")


if __name__ == "__main__":
    unittest.main()
