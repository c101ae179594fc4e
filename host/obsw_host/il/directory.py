"""A name directory on the file system: which process provides which component, now.

One file per component, ``<dir>/<Component>.provider``, holds the JSON ``{"address",
"pid", "node"}`` of the process that serves it, written atomically (write, then rename). A
provider that restarts simply writes its new address over the old one; a user that finds an
entry whose process is gone treats the name as not (yet) provided. No port table: sockets are
named after the node and its pid under ``<dir>/sockets``.
"""

import json
import os
import tempfile

DEFAULT_DIR_ENV = "OBSW_IL_DIR"


def default_directory():
    """``$OBSW_IL_DIR``, or a per-user directory under the temporary directory."""
    env = os.environ.get(DEFAULT_DIR_ENV)
    if env:
        return env
    uid = os.getuid() if hasattr(os, "getuid") else 0
    return os.path.join(tempfile.gettempdir(), "obsw-il-%d" % uid)


def pid_alive(pid):
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


class Directory:
    def __init__(self, path=None):
        self.path = path or default_directory()
        self.sockets = os.path.join(self.path, "sockets")
        os.makedirs(self.sockets, exist_ok=True)

    def _entry(self, name):
        if not name or "/" in name or name.startswith("."):
            raise ValueError("bad component name %r" % (name,))
        return os.path.join(self.path, name + ".provider")

    def register(self, name, address, node=""):
        entry = {"address": address, "pid": os.getpid(), "node": node}
        fd, tmp = tempfile.mkstemp(dir=self.path, prefix="." + name)
        with os.fdopen(fd, "w") as f:
            json.dump(entry, f)
        os.replace(tmp, self._entry(name))

    def unregister(self, name, address=None):
        """Remove ``name``; with ``address``, only if the entry is still ours."""
        if address is not None:
            entry = self.read(name)
            if entry is None or entry.get("address") != address:
                return
        try:
            os.remove(self._entry(name))
        except FileNotFoundError:
            pass

    def read(self, name):
        try:
            with open(self._entry(name)) as f:
                return json.load(f)
        except (FileNotFoundError, ValueError):
            return None

    def lookup(self, name):
        """The address of the live process providing ``name``, or None."""
        entry = self.read(name)
        if entry is None or not pid_alive(entry.get("pid", -1)):
            return None
        return entry.get("address")

    def names(self):
        """Components with an entry whose process is alive."""
        out = []
        for fn in sorted(os.listdir(self.path)):
            if fn.endswith(".provider") and self.lookup(fn[: -len(".provider")]):
                out.append(fn[: -len(".provider")])
        return out

    def socket_path(self, node):
        return os.path.join(self.sockets, "%s-%d.sock" % (node, os.getpid()))

    def sweep(self):
        """Remove socket files of processes that are gone; return how many."""
        n = 0
        for fn in os.listdir(self.sockets):
            stem = fn[:-5] if fn.endswith(".sock") else None
            pid = stem.rsplit("-", 1)[-1] if stem and "-" in stem else ""
            if pid.isdigit() and not pid_alive(int(pid)):
                try:
                    os.remove(os.path.join(self.sockets, fn))
                    n += 1
                except FileNotFoundError:
                    pass
        return n
