"""The context store: small JSON states that survive a power cut at any instant.

``save(name, value)`` writes ``name.new`` in full, then renames it over ``name``. Rename
replaces atomically on POSIX and on littlefs; where it refuses to replace (FAT), the old
file is removed first, and ``load`` then finds the complete ``.new``. Every file carries its
length and CRC-32, so a half-written file is recognised and ignored: whenever power goes,
``load`` returns the old state or the new one, never a broken one. MicroPython has no
``os.fsync``; the file is closed (flushed) before the rename and ``os.sync`` is called
where the port has it.

A cut between the remove and the rename leaves the complete ``.new`` as the only copy; the
next ``save`` first renames it into place, and only then writes a new ``.new``, so a second
cut during that write cannot take the last copy with it. Files are parsed with their JSON
nesting bounded (``obsw.jsonsafe``).

The file system is passed in (``fs``) so tests can cut the power after any operation.
"""

import json
import os

from obsw import jsonsafe
from obsw.crc import crc32

_MAGIC = b"OBSWCTX1"
_NEW = ".new"


class OsFs:
    """The real file system through ``os`` and ``open``."""

    def open(self, path, mode):
        return open(path, mode)

    def rename(self, old, new):
        os.rename(old, new)

    def remove(self, path):
        os.remove(path)

    def exists(self, path):
        try:
            os.stat(path)
            return True
        except OSError:
            return False

    def makedirs(self, path):
        part = "/" if path.startswith("/") else ""
        for piece in path.split("/"):
            if not piece:
                continue
            part += piece
            if not self.exists(part):
                os.mkdir(part)
            part += "/"

    def flush(self, f):
        """Push a written file towards the medium before it is renamed into place."""
        f.flush()
        fsync = getattr(os, "fsync", None)
        if fsync is not None:
            fsync(f.fileno())

    def sync(self, folder):
        sync = getattr(os, "sync", None)  # MicroPython ports with a block device
        if sync is not None:
            sync()
        elif hasattr(os, "O_DIRECTORY"):  # CPython on POSIX: make the rename durable
            fd = os.open(folder or ".", os.O_RDONLY | os.O_DIRECTORY)
            try:
                os.fsync(fd)
            finally:
                os.close(fd)


def encode(value):
    body = json.dumps(value).encode()
    return _MAGIC + b" %08x %d\n" % (crc32(body), len(body)) + body


def decode(data):
    """The value in a file's bytes; ValueError if the file is incomplete or damaged."""
    if not data.startswith(_MAGIC + b" "):
        raise ValueError("context file header missing")
    nl = data.find(b"\n")
    if nl < 0:
        raise ValueError("context file header incomplete")
    head = data[len(_MAGIC) + 1 : nl].split(b" ")
    if len(head) != 2:
        raise ValueError("context file header malformed")
    crc = int(head[0], 16)
    size = int(head[1])
    body = data[nl + 1 :]
    if len(body) != size:
        raise ValueError("context file has %d bytes of %d" % (len(body), size))
    if crc32(body) != crc:
        raise ValueError("context file checksum mismatch")
    return jsonsafe.loads(body)


class Store:
    """Named JSON values in the folder ``root`` (created if missing)."""

    def __init__(self, root, fs=None):
        self.fs = fs if fs is not None else OsFs()
        self.root = root.rstrip("/") if root != "/" else root
        self.saves = 0
        self.recovered = 0  # loads that found only the new file (a cut between remove and rename)
        self.damaged = 0  # files ignored because they were incomplete
        self.rejected = []  # names set aside (``NAME.bad``) or refused by their service
        if hasattr(self.fs, "makedirs"):
            self.fs.makedirs(self.root)

    def path(self, name):
        if not name or "/" in name or name.startswith("."):
            raise ValueError("context name must be a plain file name, got %r" % (name,))
        return self.root + "/" + name

    def save(self, name, value):
        path = self.path(name)
        new = path + _NEW
        data = encode(value)
        fs = self.fs
        if fs.exists(new) and not self._valid(path) and self._valid(new):
            # the last save was cut between remove and rename: .new is the only copy
            if fs.exists(path):
                fs.remove(path)
            fs.rename(new, path)
        f = fs.open(new, "wb")
        try:
            f.write(data)
            fs.flush(f)
        finally:
            f.close()
        try:
            fs.rename(new, path)
        except OSError:
            # a file system whose rename does not replace: old first, then the new into place
            if fs.exists(path):
                fs.remove(path)
            fs.rename(new, path)
        fs.sync(self.root)
        self.saves += 1

    def _valid(self, path):
        if not self.fs.exists(path):
            return False
        try:
            f = self.fs.open(path, "rb")
            try:
                decode(f.read())
            finally:
                f.close()
            return True
        except (OSError, ValueError):
            return False

    def _read(self, path):
        fs = self.fs
        if not fs.exists(path):
            return None
        try:
            f = fs.open(path, "rb")
            try:
                data = f.read()
            finally:
                f.close()
            return (decode(data),)
        except (OSError, ValueError):
            self.damaged += 1
            return None

    def load(self, name, default=None):
        """The last value saved under ``name`` completely, or ``default``."""
        path = self.path(name)
        got = self._read(path)
        if got is not None:
            return got[0]
        got = self._read(path + _NEW)
        if got is not None:
            self.recovered += 1
            return got[0]
        if self.fs.exists(path):  # damaged, and no new copy: not a cut, set aside for good
            self.set_aside(name)
        return default

    def set_aside(self, name):
        """Keep ``name``'s file as ``NAME.bad`` (never read again) and note it in
        ``rejected``: the unit starts clean, the OBC reports it."""
        path = self.path(name)
        fs = self.fs
        try:
            if fs.exists(path + ".bad"):
                fs.remove(path + ".bad")
            if fs.exists(path):
                fs.rename(path, path + ".bad")
        except OSError:
            pass
        if name not in self.rejected:
            self.rejected.append(name)

    def delete(self, name):
        path = self.path(name)
        for p in (path, path + _NEW):
            if self.fs.exists(p):
                self.fs.remove(p)
