"""A file system in memory that loses power at a chosen operation (test helper for obsw.store).

Only what reached ``files`` survives a cut; a write cut short leaves the first ``partial``
octets. ``replacing=False`` plays FAT, whose rename refuses to replace an existing file.
"""


class PowerCut(Exception):
    pass


class _File:
    def __init__(self, fs, path, data=None):
        self.fs = fs
        self.path = path
        self.data = data

    def write(self, data):
        self.fs._op("write", self.path, bytes(data))
        return len(data)

    def read(self):
        return self.data

    def flush(self):
        pass

    def close(self):
        pass


class SimFs:
    def __init__(self, files=None, cut_at=None, partial=0, replacing=True):
        self.files = files if files is not None else {}
        self.cut_at = cut_at  # the operation (counted from 1) during which power goes
        self.partial = partial  # octets of a cut write that still reach the medium
        self.replacing = replacing
        self.ops = 0

    def _op(self, kind, path, data=b"", new=None):
        self.ops += 1
        if self.ops == self.cut_at:
            if kind == "write":
                self.files[path] = self.files[path] + data[: self.partial]
            raise PowerCut("%s %s" % (kind, path))
        if kind == "create":
            self.files[path] = b""
        elif kind == "write":
            self.files[path] = self.files[path] + data
        elif kind == "rename":
            self.files[new] = self.files.pop(path)
        elif kind == "remove":
            del self.files[path]

    def open(self, path, mode):
        if "w" in mode:
            self._op("create", path)
            return _File(self, path)
        if path not in self.files:
            raise OSError(2, "no such file")
        return _File(self, path, self.files[path])

    def rename(self, old, new):
        if old not in self.files:
            raise OSError(2, "no such file")
        if new in self.files and not self.replacing:
            raise OSError(17, "file exists")
        self._op("rename", old, new=new)

    def remove(self, path):
        if path not in self.files:
            raise OSError(2, "no such file")
        self._op("remove", path)

    def exists(self, path):
        return path in self.files

    def flush(self, f):
        pass

    def sync(self, folder):
        pass
