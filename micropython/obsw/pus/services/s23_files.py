"""ST[23] file management: the onboard filestore by standard requests, and file copies to and
from the ground coordinated with the CFDP entity.

Paths are ``PREFIX:/folder/name``; each prefix is a filestore the spacecraft database maps
to a CFDP entity (``filestores``). The onboard one (``local``) is the ``filestore`` given,
an ``obsw.cfdp.filestore.Filestore`` rooted in one directory. A path whose '..' parts climb
out of the root or out of its repository, or that names an unknown prefix, fails with
``FAILURE_PATH``; a filestore refusal (no such file, exists, locked, not empty) with
``FAILURE_FILESTORE``. Locked files cannot be deleted, renamed, moved or overwritten.

Copies (TC[23,14]) and moves (TC[23,15]) inside the onboard filestore are done at once.
Between the onboard filestore and the ground they go through the ``RemoteFileCopy``
component of the CFDP entity (``obsw.cfdp.remote_copy``) on the interaction layer ``node``:
the request completes once the transfer has started; the operation then continues under its
operation ID, which TC[23,16..21] suspend, resume and abort (by ID or by path), and TM[23,23]
reports (periodically once enabled by TC[23,22]). Progress comes as the component's status
updates and, after a restart, by asking the component every ``poll_every`` cycles. An event
marks the end of every remote copy. Locks, maximum sizes and operations persist in the
context store.
"""

from obsw.cfdp.filestore import normalize
from obsw.cfdp.remote_copy import REMOTE_COPY_NAME
from obsw.pus.messages import (
    SERVICE_FILE_MANAGEMENT,
    TC_FILE_ABORT_COPY,
    TC_FILE_ABORT_COPY_IN_PATH,
    TC_FILE_COPY,
    TC_FILE_CREATE,
    TC_FILE_CREATE_DIRECTORY,
    TC_FILE_DELETE,
    TC_FILE_DELETE_DIRECTORY,
    TC_FILE_DISABLE_COPY_STATUS_REPORTS,
    TC_FILE_ENABLE_COPY_STATUS_REPORTS,
    TC_FILE_FIND,
    TC_FILE_LOCK,
    TC_FILE_MOVE,
    TC_FILE_RENAME_DIRECTORY,
    TC_FILE_REPORT_ATTRIBUTES,
    TC_FILE_REPORT_REPOSITORY_SUMMARY,
    TC_FILE_RESUME_COPY,
    TC_FILE_RESUME_COPY_IN_PATH,
    TC_FILE_SUSPEND_COPY,
    TC_FILE_SUSPEND_COPY_IN_PATH,
    TC_FILE_UNLOCK,
    TM_FILE_ATTRIBUTE_REPORT,
    TM_FILE_COPY_STATUS_REPORT,
    TM_FILE_FOUND_REPORT,
    TM_FILE_REPOSITORY_SUMMARY_REPORT,
)
from obsw.pus.services.s23_copies import CopyOperations, _fs_error, _path_error
from obsw.pus.services.s23_layouts import (
    ATTRIBUTES,
    CREATE,
    DIRECTORY,
    FILE,
    FIND,
    FOUND,
    OBJECT_DIRECTORY,
    OBJECT_FILE,
    RENAME_DIRECTORY,
    REPOSITORY,
    SUMMARY,
)

EVENT_COPY_COMPLETED = 0xFF23
EVENT_COPY_FAILED = 0xFF24


def match(pattern, name):
    """Shell-style matching of ``name`` against ``pattern`` with '*' and '?'."""
    p = 0
    n = 0
    star = -1
    back = 0
    while n < len(name):
        if p < len(pattern) and (pattern[p] == "?" or pattern[p] == name[n]):
            p += 1
            n += 1
        elif p < len(pattern) and pattern[p] == "*":
            star = p
            back = n
            p += 1
        elif star >= 0:
            p = star + 1
            back += 1
            n = back
        else:
            return False
    while p < len(pattern) and pattern[p] == "*":
        p += 1
    return p == len(pattern)


class FileManagement(CopyOperations):
    """The service 23 provider (see the module text).

    ``prefixes`` maps path prefixes to CFDP entity ids (``Sdb.filestores``); ``local`` names
    the onboard one.
    """

    SERVICE = SERVICE_FILE_MANAGEMENT
    REPORTS = (
        TM_FILE_ATTRIBUTE_REPORT,
        TM_FILE_FOUND_REPORT,
        TM_FILE_REPOSITORY_SUMMARY_REPORT,
        TM_FILE_COPY_STATUS_REPORT,
    )
    NAME = "s23"
    HANDLERS = (
        (TC_FILE_CREATE, "create"),
        (TC_FILE_DELETE, "delete"),
        (TC_FILE_REPORT_ATTRIBUTES, "report_attributes"),
        (TC_FILE_LOCK, "lock"),
        (TC_FILE_UNLOCK, "unlock"),
        (TC_FILE_FIND, "find"),
        (TC_FILE_CREATE_DIRECTORY, "create_directory"),
        (TC_FILE_DELETE_DIRECTORY, "delete_directory"),
        (TC_FILE_RENAME_DIRECTORY, "rename_directory"),
        (TC_FILE_REPORT_REPOSITORY_SUMMARY, "report_summary"),
        (TC_FILE_COPY, "copy"),
        (TC_FILE_MOVE, "move"),
        (TC_FILE_SUSPEND_COPY, "suspend"),
        (TC_FILE_RESUME_COPY, "resume"),
        (TC_FILE_ABORT_COPY, "abort"),
        (TC_FILE_SUSPEND_COPY_IN_PATH, "suspend_in_path"),
        (TC_FILE_RESUME_COPY_IN_PATH, "resume_in_path"),
        (TC_FILE_ABORT_COPY_IN_PATH, "abort_in_path"),
        (TC_FILE_ENABLE_COPY_STATUS_REPORTS, "enable_reports"),
        (TC_FILE_DISABLE_COPY_STATUS_REPORTS, "disable_reports"),
    )

    def __init__(
        self,
        filestore,
        prefixes=None,
        local="SAT",
        node=None,
        timeout=5.0,
        poll_every=5,
        max_found=64,
        keep_done=16,
        events=(EVENT_COPY_COMPLETED, EVENT_COPY_FAILED),
        component=REMOTE_COPY_NAME,
    ):
        super().__init__()
        self.fs = filestore
        self.prefixes = dict(prefixes) if prefixes else {local: 0}
        self.local = local
        self.node = node
        self.timeout = timeout
        self.poll_every = poll_every
        self.max_found = max_found
        self.keep_done = keep_done
        self.events = events
        self.component = component
        self.locked = set()
        self.max_sizes = {}
        self.ops = {}  # operation ID -> dict
        self.report_interval = 0  # cycles between TM[23,23]; 0: off
        self._report_countdown = 0
        self._poll_countdown = poll_every

    # -------------------------------------------------------------------------- context

    def context(self):
        return {
            "locked": sorted(self.locked),
            "max_sizes": [[k, v] for k, v in self.max_sizes.items()],
            "ops": list(self.ops.values()),
            "report_interval": self.report_interval,
        }

    def restore(self, ctx):
        locked = set(ctx["locked"])
        sizes = {k: v for k, v in ctx["max_sizes"]}
        ops = {}
        for op in ctx["ops"]:
            ops[op["id"]] = op
        self.locked, self.max_sizes, self.ops = locked, sizes, ops
        self.report_interval = ctx.get("report_interval", 0)
        self._report_countdown = self.report_interval

    # -------------------------------------------------------------------------- paths

    def split(self, path):
        """(prefix, normalised name) of ``PREFIX:/a/b``; FAILURE_PATH when it cannot be."""
        if not isinstance(path, str) or "\x00" in path:
            raise _path_error(path, "not a path")
        prefix, sep, rest = path.partition(":")
        if not sep:
            prefix, rest = self.local, path
        if prefix not in self.prefixes:
            raise _path_error(path, "no filestore %r" % prefix)
        name = normalize(rest)
        if name is None:
            raise _path_error(path, "escapes the filestore root")
        return prefix, name

    def _join(self, repository, name):
        prefix, repo = self.split(repository)
        if not isinstance(name, str) or not name:
            raise _path_error(name, "empty name")
        full = normalize(repo + "/" + name)
        if full is None or (repo and full != repo and not full.startswith(repo + "/")):
            raise _path_error(repository + "/" + name, "escapes its repository")
        if not full:
            raise _path_error(repository + "/" + name, "names the repository itself")
        return prefix, full

    def local_path(self, repository, name=None):
        """The onboard filestore name of a repository (and a name in it)."""
        if name is None:
            prefix, full = self.split(repository)
        else:
            prefix, full = self._join(repository, name)
        if prefix != self.local:
            raise _path_error(repository, "not the onboard filestore %s" % self.local)
        return full

    def _file(self, tc):
        return self.local_path(tc["repository"], tc["file"])

    def _is_file(self, name):
        return self.fs.exists(name) and not self.fs.is_dir(name)

    def _need_file(self, name):
        if not self._is_file(name):
            raise _fs_error("no file %s" % name)

    def _unlocked(self, name):
        if name in self.locked:
            raise _fs_error("%s is locked" % name)

    def _fs(self, fn, *args):
        try:
            return fn(*args)
        except OSError as e:
            raise _fs_error(str(e)) from None

    # -------------------------------------------------------------------------- files

    def create(self, req):
        tc = req.decode(CREATE)
        name = self._file(tc)
        if self.fs.exists(name):
            raise _fs_error("%s exists" % name)
        req.start()
        self._fs(self.fs.write_bytes, name, b"")
        self.max_sizes[name] = tc["max_size"]
        self.persist()

    def delete(self, req):
        name = self._file(req.decode(FILE))
        self._need_file(name)
        self._unlocked(name)
        req.start()
        self._fs(self.fs.delete, name)
        self.max_sizes.pop(name, None)
        self.persist()

    def report_attributes(self, req):
        tc = req.decode(FILE)
        name = self._file(tc)
        self._need_file(name)
        data = ATTRIBUTES.pack(
            {
                "repository": tc["repository"],
                "file": tc["file"],
                "size": self._fs(self.fs.size, name),
                "max_size": self.max_sizes.get(name, 0),
                "locked": name in self.locked,
            }
        )
        req.report(TM_FILE_ATTRIBUTE_REPORT, data)

    def _lock(self, req, locked):
        name = self._file(req.decode(FILE))
        self._need_file(name)
        req.start()
        if locked:
            self.locked.add(name)
        else:
            self.locked.discard(name)
        self.persist()

    def lock(self, req):
        self._lock(req, True)

    def unlock(self, req):
        self._lock(req, False)

    def _walk(self, top, out, limit):
        for n in self._fs(self.fs.listdir, top):
            full = top + "/" + n if top else n
            if self.fs.is_dir(full):
                self._walk(full, out, limit)
            else:
                out.append(full)
            if len(out) > limit:
                return

    def find(self, req):
        tc = req.decode(FIND)
        top = self.local_path(tc["repository"])
        if not self.fs.is_dir(top):
            raise _fs_error("no directory %s" % top)
        names = []
        self._walk(top, names, 100000)
        found = []
        for full in names:
            rel = full[len(top) + 1 :] if top else full
            if match(tc["pattern"], rel) or match(tc["pattern"], rel.split("/")[-1]):
                found.append("%s:/%s" % (self.local, full))
        if len(found) > self.max_found:
            found = found[: self.max_found]
        data = FOUND.pack(
            {"repository": tc["repository"], "pattern": tc["pattern"], "paths": found}
        )
        req.report(TM_FILE_FOUND_REPORT, data)

    # -------------------------------------------------------------------------- directories

    def create_directory(self, req):
        tc = req.decode(DIRECTORY)
        name = self.local_path(tc["repository"], tc["directory"])
        if self.fs.exists(name):
            raise _fs_error("%s exists" % name)
        req.start()
        self._fs(self.fs.mkdir, name)

    def delete_directory(self, req):
        tc = req.decode(DIRECTORY)
        name = self.local_path(tc["repository"], tc["directory"])
        if not self.fs.is_dir(name):
            raise _fs_error("no directory %s" % name)
        if self._fs(self.fs.listdir, name):
            raise _fs_error("directory %s is not empty" % name)
        req.start()
        self._fs(self.fs.rmdir, name)

    def rename_directory(self, req):
        tc = req.decode(RENAME_DIRECTORY)
        old = self.local_path(tc["repository"], tc["old"])
        new = self.local_path(tc["repository"], tc["new"])
        if not self.fs.is_dir(old):
            raise _fs_error("no directory %s" % old)
        if self.fs.exists(new):
            raise _fs_error("%s exists" % new)
        for name in self.locked:
            if name.startswith(old + "/"):
                raise _fs_error("%s holds locked file %s" % (old, name))
        req.start()
        self._fs(self._rename_tree, old, new)

    def _rename_tree(self, old, new):
        try:
            self.fs.rename(old, new)  # a directory renames at once where the filestore can
            return
        except OSError:
            pass
        self.fs.mkdir(new)
        for n in self.fs.listdir(old):
            src = old + "/" + n
            if self.fs.is_dir(src):
                self._rename_tree(src, new + "/" + n)
            else:
                self.fs.rename(src, new + "/" + n)
        self.fs.rmdir(old)

    def report_summary(self, req):
        tc = req.decode(REPOSITORY)
        top = self.local_path(tc["repository"])
        if not self.fs.is_dir(top):
            raise _fs_error("no directory %s" % top)
        objects = []
        for n in self._fs(self.fs.listdir, top):
            full = top + "/" + n if top else n
            kind = OBJECT_DIRECTORY if self.fs.is_dir(full) else OBJECT_FILE
            objects.append({"type": kind, "name": n})
        data = SUMMARY.pack({"repository": tc["repository"], "objects": objects})
        req.report(TM_FILE_REPOSITORY_SUMMARY_REPORT, data)
