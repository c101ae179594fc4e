"""A CFDP filestore rooted in one configured directory (the onboard virtual file system)."""

import os

from obsw.cfdp.filestore import FilestoreError, OsFilestore

ENV_ROOT = "OBSW_FILESTORE"


def default_root():
    """The filestore root: $OBSW_FILESTORE, else ./filestore."""
    return os.environ.get(ENV_ROOT) or os.path.join(os.getcwd(), "filestore")


class RootedFilestore(OsFilestore):
    """Files under ``root`` only: '..' climbing out and symbolic links pointing out are refused."""

    def __init__(self, root=None):
        root = os.path.realpath(root or default_root())
        os.makedirs(root, exist_ok=True)
        super().__init__(root)
        self._real_root = root

    def path(self, name):
        p = super().path(name)
        real = os.path.realpath(p)
        if real != self._real_root and not real.startswith(self._real_root + os.sep):
            raise FilestoreError("name escapes the filestore: %s" % name, name)
        return p

    def write_atomic(self, name, data):
        # the core's version plus fsync, so a crash leaves the old or the new copy on disk
        tmp = self.path(name + ".new")
        with open(tmp, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, self.path(name))
