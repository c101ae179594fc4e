"""The filestore interface the CFDP entity works through, an in-memory one for tests and
benchmarks, one over ``os`` that runs on both interpreters, and filestore request execution."""

import os

from obsw.cfdp.defs import (
    FS_APPEND_FILE,
    FS_CREATE_DIRECTORY,
    FS_CREATE_FILE,
    FS_DELETE_FILE,
    FS_DENY_DIRECTORY,
    FS_DENY_FILE,
    FS_NOT_PERFORMED,
    FS_REMOVE_DIRECTORY,
    FS_RENAME_FILE,
    FS_REPLACE_FILE,
    FS_SUCCESS,
)
from obsw.cfdp.tlv import FilestoreResponse


class FilestoreError(OSError):
    """A filestore operation that failed; ``name`` is the file it concerned."""

    def __init__(self, msg, name=None):
        super().__init__(msg)
        self.name = name


class Filestore:
    """What the entity needs from a filestore. Names are '/'-separated strings.

    Subclasses implement the methods that raise NotImplementedError; the others are built on them.
    Read handles have ``read(offset, n)`` and ``close()``; write handles ``write(offset, data)``,
    ``close()`` and optionally ``sync()`` (the data on the medium before it returns).
    """

    def open_read(self, name):
        raise NotImplementedError

    def open_write(self, name, truncate=True):
        raise NotImplementedError

    def size(self, name):
        raise NotImplementedError

    def exists(self, name):
        raise NotImplementedError

    def is_dir(self, name):
        raise NotImplementedError

    def delete(self, name):
        raise NotImplementedError

    def rename(self, old, new):
        """Rename, replacing ``new`` if it exists (the atomic step of ``write_atomic``)."""
        raise NotImplementedError

    def mkdir(self, name):
        raise NotImplementedError

    def rmdir(self, name):
        raise NotImplementedError

    def listdir(self, name):
        raise NotImplementedError

    # built on the above
    def read_bytes(self, name, offset=0, n=-1):
        h = self.open_read(name)
        try:
            if n < 0:
                n = self.size(name) - offset
            return h.read(offset, n)
        finally:
            h.close()

    def write_bytes(self, name, data):
        h = self.open_write(name, True)
        try:
            h.write(0, data)
        finally:
            h.close()

    def write_atomic(self, name, data):
        """Write a new copy next to ``name`` and rename it over, so readers see old or new."""
        tmp = name + ".new"
        self.write_bytes(tmp, data)
        self.rename(tmp, name)

    def append_file(self, dst, src):
        data = self.read_bytes(src)
        h = self.open_write(dst, False)
        try:
            h.write(self.size(dst), data)
        finally:
            h.close()

    def copy_file(self, dst, src):
        self.write_bytes(dst, self.read_bytes(src))


class _MemHandle:
    def __init__(self, buf):
        self.buf = buf

    def read(self, offset, n):
        return bytes(memoryview(self.buf)[offset : offset + n])

    def write(self, offset, data):
        buf = self.buf
        size = len(buf)
        if offset == size:
            buf.extend(data)
        elif offset + len(data) <= size:
            buf[offset : offset + len(data)] = data
        else:
            if offset > size:
                buf.extend(bytes(offset - size))
            buf[offset:] = data

    def sync(self):
        pass

    def close(self):
        pass


class MemoryFilestore(Filestore):
    """Files as bytearrays in a dict; directories as a set. For tests and benchmarks."""

    def __init__(self, files=None):
        self.files = {}
        self.dirs = set([""])
        for k in files or {}:
            self.files[self._n(k)] = bytearray(files[k])

    @staticmethod
    def _n(name):
        if "\0" in name:
            raise FilestoreError("a NUL in the file name %r" % name, name)
        return name.strip("/")

    def _parent_ok(self, n):
        i = n.rfind("/")
        return (n[:i] if i >= 0 else "") in self.dirs

    def open_read(self, name):
        n = self._n(name)
        if n not in self.files:
            raise FilestoreError("no such file: %s" % name, name)
        return _MemHandle(self.files[n])

    def open_write(self, name, truncate=True):
        n = self._n(name)
        if n in self.dirs or not self._parent_ok(n):
            raise FilestoreError("cannot write file: %s" % name, name)
        if truncate or n not in self.files:
            self.files[n] = bytearray()
        return _MemHandle(self.files[n])

    def size(self, name):
        n = self._n(name)
        if n not in self.files:
            raise FilestoreError("no such file: %s" % name, name)
        return len(self.files[n])

    def exists(self, name):
        n = self._n(name)
        return n in self.files or n in self.dirs

    def is_dir(self, name):
        return self._n(name) in self.dirs

    def delete(self, name):
        n = self._n(name)
        if n not in self.files:
            raise FilestoreError("no such file: %s" % name, name)
        del self.files[n]

    def rename(self, old, new):
        o = self._n(old)
        n = self._n(new)
        if o not in self.files or n in self.dirs or not self._parent_ok(n):
            raise FilestoreError("cannot rename %s to %s" % (old, new), old)
        self.files[n] = self.files.pop(o)

    def mkdir(self, name):
        n = self._n(name)
        if n in self.dirs or n in self.files or not self._parent_ok(n):
            raise FilestoreError("cannot create directory: %s" % name, name)
        self.dirs.add(n)

    def rmdir(self, name):
        n = self._n(name)
        if n not in self.dirs or not n:
            raise FilestoreError("no such directory: %s" % name, name)
        for k in list(self.files) + list(self.dirs):
            if k.startswith(n + "/"):
                raise FilestoreError("directory not empty: %s" % name, name)
        self.dirs.remove(n)

    def listdir(self, name):
        n = self._n(name)
        if n not in self.dirs:
            raise FilestoreError("no such directory: %s" % name, name)
        pre = n + "/" if n else ""
        out = []
        for k in list(self.files) + list(self.dirs):
            if k and k.startswith(pre) and "/" not in k[len(pre) :]:
                out.append(k[len(pre) :])
        out.sort()
        return out


class _FileHandle:
    def __init__(self, f):
        self.f = f
        self.pos = 0

    def read(self, offset, n):
        f = self.f
        if offset != self.pos:
            f.seek(offset)
        data = f.read(n)
        self.pos = offset + len(data)
        return data

    def write(self, offset, data):
        f = self.f
        if offset != self.pos:
            f.seek(offset)
        f.write(data)
        self.pos = offset + len(data)

    def sync(self):
        """On the medium before this returns (``os.fsync`` where the interpreter has it)."""
        f = self.f
        f.flush()
        fsync = getattr(os, "fsync", None)
        if fsync is not None:
            fsync(f.fileno())

    def close(self):
        self.f.close()


_S_IFDIR = 0x4000


def normalize(name):
    """'/'-separated name without '.', '..' or empty parts; None if '..' climbs above the top."""
    parts = []
    for p in name.replace("\\", "/").split("/"):
        if p in ("", "."):
            continue
        if p == "..":
            if not parts:
                return None
            parts.pop()
        else:
            parts.append(p)
    return "/".join(parts)


class OsFilestore(Filestore):
    """Files under one directory through ``os`` and ``open`` (both interpreters).

    Names are taken relative to ``root`` (a leading '/' does not escape it) and a name whose
    '..' parts would climb above ``root`` is refused.
    """

    def __init__(self, root="."):
        self.root = root.rstrip("/") or "/"

    def path(self, name):
        if "\0" in name:  # no file system takes one; refused as the standard's filestore error
            raise FilestoreError("a NUL in the file name %r" % name, name)
        n = normalize(name)
        if n is None:
            raise FilestoreError("name escapes the filestore: %s" % name, name)
        return self.root + "/" + n if n else self.root

    def _stat(self, name):
        try:
            return os.stat(self.path(name))
        except OSError:
            return None

    def open_read(self, name):
        try:
            return _FileHandle(open(self.path(name), "rb"))
        except FilestoreError:
            raise
        except OSError:
            raise FilestoreError("cannot read file: %s" % name, name) from None

    def open_write(self, name, truncate=True):
        p = self.path(name)
        try:
            if truncate or self._stat(name) is None:
                f = open(p, "w+b")
            else:
                f = open(p, "r+b")
        except OSError:
            raise FilestoreError("cannot write file: %s" % name, name) from None
        return _FileHandle(f)

    def size(self, name):
        st = self._stat(name)
        if st is None or st[0] & _S_IFDIR:
            raise FilestoreError("no such file: %s" % name, name)
        return st[6]

    def exists(self, name):
        return self._stat(name) is not None

    def is_dir(self, name):
        st = self._stat(name)
        return st is not None and bool(st[0] & _S_IFDIR)

    def _os(self, fn, msg, name, *args):
        try:
            fn(*args)
        except OSError:
            raise FilestoreError(msg % name, name) from None

    def delete(self, name):
        if self.is_dir(name):
            raise FilestoreError("is a directory: %s" % name, name)
        self._os(os.remove, "cannot delete file: %s", name, self.path(name))

    def rename(self, old, new):
        self._os(os.rename, "cannot rename %s", old, self.path(old), self.path(new))

    def mkdir(self, name):
        self._os(os.mkdir, "cannot create directory: %s", name, self.path(name))

    def rmdir(self, name):
        self._os(os.rmdir, "cannot remove directory: %s", name, self.path(name))

    def listdir(self, name):
        try:
            out = sorted(os.listdir(self.path(name)))
        except OSError:
            raise FilestoreError("no such directory: %s" % name, name) from None
        return out


def execute_request(fs, req):
    """Carry out one filestore request; the FilestoreResponse says how it went (table 5-18)."""
    a = req.action
    first = req.first
    second = req.second
    st = FS_SUCCESS
    msg = b""
    try:
        if a == FS_CREATE_FILE:
            try:
                fs.write_bytes(first, b"")
            except OSError:
                st = 1
        elif a == FS_DELETE_FILE:
            if not fs.exists(first) or fs.is_dir(first):
                st = 1
            else:
                fs.delete(first)
        elif a == FS_RENAME_FILE:
            if not fs.exists(first):
                st = 1
            elif fs.exists(second):
                st = 2
            else:
                fs.rename(first, second)
        elif a in (FS_APPEND_FILE, FS_REPLACE_FILE):
            if not fs.exists(first) or fs.is_dir(first):
                st = 1
            elif not fs.exists(second) or fs.is_dir(second):
                st = 2
            elif a == FS_APPEND_FILE:
                fs.append_file(first, second)
            else:
                fs.copy_file(first, second)
        elif a == FS_CREATE_DIRECTORY:
            try:
                fs.mkdir(first)
            except OSError:
                st = 1
        elif a == FS_REMOVE_DIRECTORY:
            if not fs.is_dir(first):
                st = 1
            else:
                fs.rmdir(first)
        elif a == FS_DENY_FILE:
            if fs.exists(first) and not fs.is_dir(first):
                fs.delete(first)
        elif a == FS_DENY_DIRECTORY:
            if fs.is_dir(first):
                fs.rmdir(first)
        else:
            st = FS_NOT_PERFORMED
            msg = b"unknown action"
    except OSError as e:
        # the operation was attempted and the filestore refused it: "not allowed"
        st = {FS_DELETE_FILE: 2, FS_RENAME_FILE: 3, FS_APPEND_FILE: 3, FS_REPLACE_FILE: 3}.get(
            a, 2 if a in (FS_REMOVE_DIRECTORY, FS_DENY_FILE, FS_DENY_DIRECTORY) else 1
        )
        msg = str(e).encode()[:255]
    return FilestoreResponse(a, st, first, second, msg)


def execute_requests(fs, requests):
    """Run requests in order; after the first failure the rest are reported 'not performed'."""
    out = []
    failed = False
    for r in requests:
        if failed:
            out.append(FilestoreResponse(r.action, FS_NOT_PERFORMED, r.first, r.second))
            continue
        resp = execute_request(fs, r)
        failed = resp.status != FS_SUCCESS
        out.append(resp)
    return out
