"""Finding a mission: ``locate(path)`` names the mission file of a folder, a file,
``$OBSW_MISSION`` or the nearest ``mission.json``; the sample is never used silently."""

import os

from obsw_host.errors import UserError
from obsw_host.mission.defaults import MISSION_FILE

ENV = "OBSW_MISSION"


def _file_of(path, source):
    path = os.path.abspath(os.path.expanduser(path))
    if os.path.isdir(path):
        f = os.path.join(path, MISSION_FILE)
        if not os.path.isfile(f):
            raise UserError(
                "%s%s has no %s" % (source, path, MISSION_FILE),
                expected="a mission folder (`obsw mission new NAME` writes one)",
            )
        return f
    if not os.path.isfile(path):
        raise UserError("%s%s: no such file or folder" % (source, path),
                        expected="a mission folder or its mission file")  # fmt: skip
    return path


def locate(path=None):
    """The mission file of ``path`` (folder or file), $OBSW_MISSION, or the nearest
    ``mission.json`` from the working folder up; else a one-line ``UserError``."""
    if path:
        return _file_of(path, "")
    env = os.environ.get(ENV)
    if env:
        return _file_of(env, "$%s: " % ENV)
    folder = os.getcwd()
    while True:
        f = os.path.join(folder, MISSION_FILE)
        if os.path.isfile(f):
            return f
        parent = os.path.dirname(folder)
        if parent == folder:
            break
        folder = parent
    raise UserError(
        "no mission named",
        expected="a mission folder: give DIR (or --mission DIR), set $%s, or work in a folder "
        "with a %s (`obsw mission new NAME` writes one)" % (ENV, MISSION_FILE),
    )


MAX_JSON_FILE = 8 << 20  # octets of a mission's JSON file: mission.json, sdb.json, a node
MAX_PROCEDURE = 1 << 20  # octets of a PLUTO procedure
MAX_DEPTH = 64  # nesting of a mission's JSON (obsw.jsonsafe)


class MissionFileError(OSError):
    """A mission file that is not read: a link out of its mission folder, not a regular file,
    or larger than its limit (an ``OSError``: callers report it as a file they cannot read)."""

    def __init__(self, code, text, path):
        super().__init__(code, text, path)


def read_text(path, limit=MAX_JSON_FILE, root=None):
    """The UTF-8 text of mission file ``path``, read with a size limit. ``root``: its mission
    folder; a name inside it that a symbolic link takes out of it is refused. Devices, pipes
    and folders are refused before a byte is read (a link to /dev/zero never runs away)."""
    import errno
    import stat

    if root is not None:
        top = os.path.abspath(root)
        lexical = os.path.abspath(path)
        real_top = os.path.realpath(top)
        if lexical.startswith(top + os.sep):
            real = os.path.realpath(lexical)
            if not real.startswith(real_top + os.sep):
                raise MissionFileError(
                    errno.EACCES, "a symbolic link out of the mission folder %s" % top, path
                )
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    try:
        st = os.fstat(fd)
        if stat.S_ISDIR(st.st_mode):  # said as for any file the user names (obsw_host.errors)
            raise IsADirectoryError(errno.EISDIR, os.strerror(errno.EISDIR), path)
        if not stat.S_ISREG(st.st_mode):
            raise MissionFileError(errno.EINVAL, "not a regular file", path)
        if st.st_size > limit:
            raise MissionFileError(
                errno.EFBIG, "%d octets, more than the %d a mission file may have"
                % (st.st_size, limit), path)  # fmt: skip
        with os.fdopen(fd, "rb", closefd=False) as f:
            data = f.read(limit + 1)
    finally:
        os.close(fd)
    if len(data) > limit:
        raise MissionFileError(errno.EFBIG, "more than %d octets" % limit, path)
    return data.decode("utf-8")


def loads_json(text):
    """``json.loads`` of a mission file's text with its nesting bounded (a ValueError)."""
    from obsw import jsonsafe

    return jsonsafe.loads(text, MAX_DEPTH)
