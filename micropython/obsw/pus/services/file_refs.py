"""Files named by (repository, file) in a request, through the process's ST[23] provider.

Services that load from or dump to the onboard filestore (6, 21) resolve paths as file
management does and honour its locks and maximum sizes, so one path means one file whichever
service names it: a path that escapes its repository fails with ``FAILURE_PATH``, a missing,
locked or oversized file with ``FAILURE_FILESTORE``.
"""

from obsw.pus.messages import FAILURE_FILESTORE, SERVICE_FILE_MANAGEMENT
from obsw.pus.services.s01_verification import PusFailure


def _files(app):
    files = app.services.get(SERVICE_FILE_MANAGEMENT) if app is not None else None
    if files is None:
        raise PusFailure(FAILURE_FILESTORE, "no file management service in this process")
    return files


def read_file(app, repository, file):
    """The content of a file of the onboard filestore."""
    files = _files(app)
    name = files.local_path(repository, file)
    if not files.fs.exists(name) or files.fs.is_dir(name):
        raise PusFailure(FAILURE_FILESTORE, "no file %s" % name)
    try:
        return bytes(files.fs.read_bytes(name))
    except OSError as e:
        raise PusFailure(FAILURE_FILESTORE, str(e)) from None


def writable_file(app, repository, file, size):
    """(filestore, name) of a file about to be written with ``size`` octets: checked only."""
    files = _files(app)
    name = files.local_path(repository, file)
    if name in files.locked:
        raise PusFailure(FAILURE_FILESTORE, "%s is locked" % name)
    if files.fs.is_dir(name):
        raise PusFailure(FAILURE_FILESTORE, "%s is a directory" % name)
    limit = files.max_sizes.get(name, 0)
    if limit and size > limit:
        raise PusFailure(FAILURE_FILESTORE, "%s takes at most %d octets" % (name, limit))
    folder = name.rsplit("/", 1)[0] if "/" in name else ""
    if folder and not files.fs.is_dir(folder):
        raise PusFailure(FAILURE_FILESTORE, "no directory %s" % folder)
    return files.fs, name


def split_path(path):
    """'SAT:/data/a.bin' -> ('SAT:/data', 'a.bin'): the (repository, file) of a request."""
    head, _, name = path.rpartition("/")
    if head.endswith(":"):
        head += "/"
    return head, name
