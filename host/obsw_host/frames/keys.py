"""SDLS key files on the host: generate, load, and keep sequence numbers across restarts.

The key file (format: ``obsw.frames.sdls_keys``) holds secrets: it is created readable by its
owner only, never inside a git work tree, and loading one that others can read is refused.
The state file (``KEYFILE.state`` unless named) keeps each SA's last sequence number sent and
highest accepted, so that neither end reuses nor accepts again a number after a restart.
"""

import json
import os
import stat

from obsw import jsonsafe
from obsw.frames.sdls import SecurityAssociation
from obsw.frames.sdls_gcm import GCM, GcmSecurityAssociation
from obsw.frames.sdls_keys import HMAC, KeyFileError, dump_sas, load_security, load_tm_security

ESSENTIAL_SPI = 63  # the SA of the essential (high priority) commands, on their MAP
TM_SPI_BASE = 64  # TM SAs: SPI 64 + VC ID
EP_SPI = 62  # the SA of the SDLS extended procedures (key and SA management), on its own MAP
EP_MAP = 62
MASTER_ID = 1  # the first master key, made with the key file


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
    path,
    vcids=(0,),
    essential_map=63,
    mac_length=16,
    window=64,
    ahead=None,
    allow_git=False,
    algorithm=HMAC,
    tm_vcids=(),
    ep=False,
):
    """Write a new key file: one SA per VC (SPI = VC ID + 1) and, unless ``essential_map`` is
    None, one for the essential MAP of the first VC (SPI 63), each with a fresh 256-bit key;
    ``algorithm`` "hmac-sha256", "aes-gcm" or "aes-gmac". With ``tm_vcids`` (GCM only), one
    AES-GCM SA per TM VC too (SPI = 64 + VC ID). With ``ep``, the SA of the extended procedures
    (SPI 62 on MAP 62) and the key store ``path + '.keystore'`` holding master key 1."""
    if not allow_git and inside_git_tree(path):
        raise KeyFileError("%s is inside a git work tree: keep keys out of repositories" % path)
    if algorithm == HMAC and tm_vcids:
        raise KeyFileError("TM SAs are AES-GCM: give algorithm aes-gcm or aes-gmac")

    def sa(spi, vcid, map_id=None, alg=algorithm):
        if alg == HMAC:
            return SecurityAssociation(
                spi, vcid, os.urandom(32), map_id, mac_length, 4, window, None, ahead
            )
        return GcmSecurityAssociation(
            spi, vcid, os.urandom(32), map_id, mac_length, window, None, ahead, alg
        )

    sas = [sa(v + 1, v) for v in vcids]
    if essential_map is not None:
        sas.append(sa(ESSENTIAL_SPI, vcids[0], essential_map))
    if ep:
        sas.append(sa(EP_SPI, vcids[0], EP_MAP))
    for v in tm_vcids:
        tm = sa(TM_SPI_BASE + v, v, None, GCM)
        tm.link = "tm"
        sas.append(tm)
    write_sas(path, sas)
    if ep:
        from obsw.frames.sdls_ep import ACTIVE, KeyStore

        store = KeyStore()
        store.add(MASTER_ID, os.urandom(32), ACTIVE)
        save_keystore(keystore_path(path), store, replace=False)
    return sas


def keystore_path(key_path):
    return key_path + ".keystore"


def load_keystore(path):
    """The KeyStore (``obsw.frames.sdls_ep``) at ``path``, refused when others can read it."""
    from obsw.frames.sdls_ep import EpError, KeyStore

    try:
        return KeyStore.load(read_key_file(path))
    except (EpError, ValueError, KeyError, TypeError) as e:
        raise KeyFileError("%s is not a key store: %s" % (path, e)) from None


def save_keystore(path, store, replace=True):
    """Write ``store`` to ``path`` (owner only), atomically over an existing file."""
    _write_secret(path, store.dump() + "\n", replace)


def write_sas(path, sas, replace=False):
    """Write ``sas`` as the key file ``path``, readable by its owner only; with ``replace``
    over an existing file, atomically (the old file stays whole until the new one is)."""
    _write_secret(path, dump_sas(sas) + "\n", replace)


def _write_secret(path, text, replace):
    if not replace:
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        with os.fdopen(fd, "w") as f:
            f.write(text)
        return
    _replace_private(path, text.encode())


def _replace_private(path, data):
    """Write ``data`` over ``path`` atomically, readable by its owner only: a leftover
    temporary file (of any mode, any owner's making) is removed, never reused."""
    tmp = path + ".tmp"
    try:
        os.unlink(tmp)
    except FileNotFoundError:
        pass
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    try:
        os.fchmod(fd, 0o600)  # whatever the umask
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
    os.replace(tmp, path)
    _sync_dir(path)


def _sync_dir(path):
    try:
        fd = os.open(os.path.dirname(os.path.abspath(path)), os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def state_path(key_path):
    return key_path + ".state"


def load(path, state=None, segment_header=True):
    """(TcSecurity, StateFile) of key file ``path``, with its sequence numbers restored from
    ``state`` (a path; by default ``path + '.state'``; missing is fine: a fresh file starts at
    0; False: no state file, and the StateFile is None). The TM SAs of the file, if any, are
    ``StateFile.tm`` (see ``load_all``)."""
    security, _, keeper = load_all(path, state, segment_header)
    return security, keeper


def read_key_file(path):
    """The text of key file ``path``; KeyFileError when others can read it or it is missing."""
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        raise KeyFileError("key file %s does not exist" % path) from None
    if mode & (stat.S_IRWXG | stat.S_IRWXO):
        raise KeyFileError("%s can be read by others (chmod 600 it)" % path)
    with open(path) as f:
        return f.read()


def load_all(path, state=None, segment_header=True):
    """(TcSecurity, TmSecurity or None, StateFile or None) of key file ``path``; as ``load``.
    Sending SAs that reserve IVs in blocks save the state file before each new block."""
    text = read_key_file(path)
    security = load_security(text, segment_header)
    tm = load_tm_security(text)
    if state is False:
        return security, tm, None
    keeper = StateFile(state or state_path(path), security, tm, key_path=path)
    keeper.load()
    security.on_reserve = keeper.save
    if tm is not None:
        tm.on_reserve = keeper.save
    return security, tm, keeper


class StateFile:
    """Saves ``security.context()`` (sequence numbers) with an atomic replace; with
    ``key_path``, first the highest number each SA may have sent into the key file itself
    (its ``sent`` fields): the counter is kept with the key, so deleting or resetting the
    state file cannot make a number (an IV) be sent twice under one key."""

    def __init__(self, path, security, tm=None, key_path=None):
        self.path = path
        self.security = security
        self.tm = tm
        self.key_path = key_path
        self.saves = 0
        self._floors = {}  # SPI -> the ``sent`` the key file holds

    def _sending(self):
        sas = list(self.security.sas.values())
        if self.tm is not None:
            sas += list(self.tm.sas.values())
        return sas

    def save_floors(self):
        """The key file's ``sent`` fields brought up to every SA's reservation (only the
        fields change: the file is read, changed and replaced atomically, mode 600)."""
        if self.key_path is None:
            return False
        want = {}
        for sa in self._sending():
            top = max(sa.sn_sent, sa.sn_reserved)
            if top > self._floors.get(sa.spi, 0):
                want[sa.spi] = top
        if not want:
            return False
        doc = json.loads(read_key_file(self.key_path))
        for entry in doc.get("sas", ()):
            spi = entry.get("spi")
            if spi in want and want[spi] > entry.get("sent", 0):
                entry["sent"] = want[spi]
        _replace_private(self.key_path, (json.dumps(doc) + "\n").encode())
        self._floors.update(want)
        return True

    def load(self):
        """Take back the saved numbers; False when there is no state file. One that cannot be
        read is set aside (``PATH.bad``, ``rejected`` says why) and the SAs go on from the
        numbers kept with their keys: sending never repeats one, receiving takes up the
        sender's numbers (see docs/security.md)."""
        self._floors = {sa.spi: sa.sn_sent for sa in self._sending()}
        try:
            with open(self.path, "rb") as f:
                text = f.read(1 << 20)
        except FileNotFoundError:
            return False
        try:
            ctx = jsonsafe.loads(text)
            if not isinstance(ctx, list):
                raise ValueError("expected a list of [spi, sent, top]")
            for entry in ctx:
                if not isinstance(entry, list) or len(entry) != 3:
                    raise ValueError("expected [spi, sent, top], got %r" % (entry,))
                for v in entry:
                    if not isinstance(v, int) or isinstance(v, bool) or v < 0:
                        raise ValueError("expected integers >= 0, got %r" % (entry,))
            self.security.restore(ctx)
            if self.tm is not None:
                self.tm.restore(ctx)
        except (ValueError, TypeError, IndexError) as e:
            self.rejected = "%s is not a state file: %s" % (self.path, e)
            try:
                os.replace(self.path, self.path + ".bad")
            except OSError:
                pass
            return False
        return True

    rejected = None

    def save(self):
        self.save_floors()  # the key's own counter first: it alone holds if this file goes
        ctx = self.security.context()
        if self.tm is not None:
            ctx = ctx + self.tm.context()
        _replace_private(self.path, json.dumps(ctx).encode())
        self.saves += 1


def signed_frame(security, scid, vcid, packet, map_id=1, seq=0, bypass=True):
    """One TC frame carrying ``packet`` on MAP ``map_id``, signed with the channel's SA."""
    from obsw.frames.tc import Segment, TcFrame

    data = security.apply(scid, vcid, Segment(map_id, packet).pack(), bypass)
    return TcFrame(scid, vcid, data, seq, bypass).pack()
