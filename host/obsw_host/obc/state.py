"""The OBC's state folder: where it lives by default, its lock, and clearing it.

A mission's state (context store, onboard filestore, packet stores, the interaction layer's
name directory) lives in one folder: the mission file's ``state``, ``--state``, or by default
``<user state>/<mission name>``, where the user state folder is ``$OBSW_STATE``, else
``$XDG_STATE_HOME/obsw``, else ``~/.local/state/obsw``: persistent, not the temp folder.

One OBC at a time uses a state folder: ``StateLock`` holds ``fcntl.flock`` on
``<state>/obc.lock``, a file that holds the pid of the holder. A second OBC of the same
mission finds it held and refuses (``StateLocked`` names the pid) before it touches anything.
The kernel releases the lock when its holder ends, however it ends.
"""

import errno
import fcntl
import os
import shutil

LOCK_FILE = "obc.lock"


def user_state():
    """The user's state folder for obsw (see the module text)."""
    base = os.environ.get("OBSW_STATE")
    if base:
        return base
    xdg = os.environ.get("XDG_STATE_HOME") or os.path.join(
        os.path.expanduser("~"), ".local", "state"
    )
    return os.path.join(xdg, "obsw")


def default_state(mission):
    """The default state folder of mission ``mission`` (its name)."""
    safe = "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in mission) or "mission"
    return os.path.join(user_state(), safe)


class StateLocked(Exception):
    """The state folder is in use by another OBC: ``pid`` holds it (0 if it cannot be read)."""

    def __init__(self, state, pid):
        held = "pid %d" % pid if pid else "another process"
        super().__init__("state folder %s is in use by %s (an OBC of this mission runs)" % (
            state, held))  # fmt: skip
        self.state = state
        self.pid = pid


def _holder(path):
    try:
        with open(path) as f:
            return int(f.read().strip() or 0)
    except (OSError, ValueError):
        return 0


class StateLock:
    """An exclusive lock on state folder ``state`` (see the module text)."""

    def __init__(self, state):
        self.state = state
        self.path = os.path.join(state, LOCK_FILE)
        self._fd = None

    def acquire(self):
        """Take the lock or raise ``StateLocked``; returns self."""
        os.makedirs(self.state, exist_ok=True)
        fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as e:
            os.close(fd)
            if e.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                raise StateLocked(self.state, _holder(self.path)) from None
            raise
        os.ftruncate(fd, 0)
        os.write(fd, b"%d\n" % os.getpid())
        self._fd = fd
        return self

    def release(self):
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None

    def __enter__(self):
        return self.acquire()

    def __exit__(self, *exc):
        self.release()


def reset(state):
    """Remove state folder ``state`` and all it holds; ``StateLocked`` while an OBC uses it.
    Returns False if there was nothing to remove."""
    if not os.path.isdir(state):
        return False
    with StateLock(state):
        for name in os.listdir(state):
            if name == LOCK_FILE:
                continue
            path = os.path.join(state, name)
            if os.path.isdir(path) and not os.path.islink(path):
                shutil.rmtree(path)
            else:
                os.remove(path)
    os.remove(os.path.join(state, LOCK_FILE))
    os.rmdir(state)
    return True
