"""SDLS key files on the host: generate, load, and keep sequence numbers across restarts.

The key file (format: ``obsw.frames.sdls_keys``) holds secrets: it is created readable by its
owner only, never inside a git work tree, and loading one that others can read is refused.
The state file (``KEYFILE.state`` unless named) keeps each SA's last sequence number sent and
highest accepted, so that neither end reuses nor accepts again a number after a restart.
"""

import json
import os
import stat

from obsw.frames.sdls import SecurityAssociation
from obsw.frames.sdls_keys import KeyFileError, dump_sas, load_security

ESSENTIAL_SPI = 63  # the SA of the essential (high priority) commands, on their MAP


def inside_git_tree(path):
    """True when ``path`` would be inside a git work tree (where it could be committed)."""
    d = os.path.dirname(os.path.abspath(path))
    while True:
        if os.path.exists(os.path.join(d, ".git")):
            return True
        parent = os.path.dirname(d)
        if parent == d:
            return False
        d = parent


def generate(
    path, vcids=(0,), essential_map=63, mac_length=16, window=64, ahead=None, allow_git=False
):
    """Write a new key file: one SA per VC (SPI = VC ID + 1) and, unless ``essential_map`` is
    None, one for the essential MAP of the first VC (SPI 63), each with a fresh 256-bit key."""
    if not allow_git and inside_git_tree(path):
        raise KeyFileError("%s is inside a git work tree: keep keys out of repositories" % path)
    sas = [
        SecurityAssociation(v + 1, v, os.urandom(32), None, mac_length, 4, window, None, ahead)
        for v in vcids
    ]
    if essential_map is not None:
        sas.append(
            SecurityAssociation(
                ESSENTIAL_SPI,
                vcids[0],
                os.urandom(32),
                essential_map,
                mac_length,
                4,
                window,
                None,
                ahead,
            )
        )
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    with os.fdopen(fd, "w") as f:
        f.write(dump_sas(sas) + "\n")
    return sas


def state_path(key_path):
    return key_path + ".state"


def load(path, state=None, segment_header=True):
    """(TcSecurity, StateFile) of key file ``path``, with its sequence numbers restored from
    ``state`` (a path; by default ``path + '.state'``; missing is fine: a fresh file starts at
    0; False: no state file, and the StateFile is None)."""
    mode = os.stat(path).st_mode
    if mode & (stat.S_IRWXG | stat.S_IRWXO):
        raise KeyFileError("%s can be read by others (chmod 600 it)" % path)
    with open(path) as f:
        security = load_security(f.read(), segment_header)
    if state is False:
        return security, None
    keeper = StateFile(state or state_path(path), security)
    keeper.load()
    return security, keeper


class StateFile:
    """Saves ``security.context()`` (sequence numbers) with an atomic replace."""

    def __init__(self, path, security):
        self.path = path
        self.security = security
        self.saves = 0

    def load(self):
        try:
            with open(self.path) as f:
                ctx = json.load(f)
        except FileNotFoundError:
            return False
        except ValueError as e:
            raise KeyFileError("%s is not a state file: %s" % (self.path, e)) from None
        try:
            self.security.restore(ctx)
        except (ValueError, TypeError, IndexError) as e:
            raise KeyFileError("%s is not a state file: %s" % (self.path, e)) from None
        return True

    def save(self):
        tmp = self.path + ".tmp"
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        with os.fdopen(fd, "w") as f:
            json.dump(self.security.context(), f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, self.path)
        self.saves += 1


def signed_frame(security, scid, vcid, packet, map_id=1, seq=0, bypass=True):
    """One TC frame carrying ``packet`` on MAP ``map_id``, signed with the channel's SA."""
    from obsw.frames.tc import Segment, TcFrame

    data = security.apply(scid, vcid, Segment(map_id, packet).pack(), bypass)
    return TcFrame(scid, vcid, data, seq, bypass).pack()
