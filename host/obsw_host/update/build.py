"""The ground's side of updates: Ed25519 keys, and building and signing packages.

``keygen(private)`` writes a new key pair: the private key (PEM, owner only, never inside a
git work tree) and beside it ``<private>.pub``, the public key as 64 hex digits, which goes
into the mission folder (``update.public_key``); the OBC holds only that.

``build(...)`` makes a package (format: ``obsw.update.package``) of the OBC software: the
``obsw`` and ``obsw_host`` Python packages as they are installed (``lib/``) and the mission
folder (``mission/``). Source files, not a wheel: the OBC runs a slot by putting its ``lib``
first on the units' ``sys.path``, with no installer and no dependency resolution on board,
and the third-party libraries (python-can, pyserial, crcmod) stay those of the system. With
``base`` (an earlier package of the same mission), the package is a delta: it carries only
the files whose hash differs from the base's tree, and names the base's version; the OBC
builds the slot from its running version's files and the delta, and checks every file.
"""

import datetime
import hashlib
import json
import os

from obsw.update.package import TARGETS, Reader, canonical, header
from obsw.update.signature import verify

from obsw_host.errors import UserError
from obsw_host.frames.keys import inside_git_tree

_SKIP_DIRS = ("__pycache__", ".git", ".pytest_cache", ".ruff_cache")
_SKIP_SUFFIXES = (".pyc", ".pyo", ".part", ".tmp", ".so")


class UpdateKeyError(UserError):
    """A key that cannot be made, read or used."""


def keygen(private, allow_git=False):
    """Write a new Ed25519 pair: ``private`` (PEM, 0600) and ``private + '.pub'`` (hex)."""
    from cryptography.hazmat.primitives import serialization
    from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

    if not allow_git and inside_git_tree(private):
        raise UpdateKeyError(
            "%s is inside a git work tree: keep keys out of repositories" % private
        )
    key = Ed25519PrivateKey.generate()
    pem = key.private_bytes(
        serialization.Encoding.PEM,
        serialization.PrivateFormat.PKCS8,
        serialization.NoEncryption(),
    )
    fd = os.open(private, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    with os.fdopen(fd, "wb") as f:
        f.write(pem)
    public = private + ".pub"
    with open(public, "w") as f:
        f.write(public_hex(key) + "\n")
    return public


def public_hex(private_key):
    from cryptography.hazmat.primitives import serialization

    raw = private_key.public_key().public_bytes(
        serialization.Encoding.Raw, serialization.PublicFormat.Raw
    )
    return raw.hex()


def load_private(path):
    from cryptography.hazmat.primitives import serialization
    from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

    try:
        with open(path, "rb") as f:
            key = serialization.load_pem_private_key(f.read(), password=None)
    except (OSError, ValueError, TypeError) as e:
        raise UpdateKeyError("%s: not an Ed25519 private key (%s)" % (path, e)) from None
    if not isinstance(key, Ed25519PrivateKey):
        raise UpdateKeyError("%s: not an Ed25519 private key" % path)
    if os.stat(path).st_mode & 0o077:
        raise UpdateKeyError("%s can be read by others than its owner: chmod 600 it" % path)
    return key


def load_public(path):
    """The 32 bytes of the public key file ``path`` (64 hex digits)."""
    try:
        with open(path) as f:
            raw = bytes.fromhex(f.read().strip())
    except (OSError, ValueError) as e:
        raise UpdateKeyError("%s: not an update public key (%s)" % (path, e)) from None
    if len(raw) != 32:
        raise UpdateKeyError("%s: %d bytes, an Ed25519 public key has 32" % (path, len(raw)))
    return raw


def sources(mission_dir, state=None):
    """{package path: file path} of the OBC software: lib/obsw, lib/obsw_host, mission/, the
    mission's ``state`` folder left out (default ``mission_dir/state``: what a running OBC
    keeps there, its sockets, stores and software slots, is not software)."""
    import obsw

    import obsw_host

    state = state if state is not None else os.path.join(mission_dir, "state")
    out = {}
    for prefix, root in (  # in the order of the walk: sorted
        ("lib/obsw", os.path.dirname(obsw.__file__)),
        ("lib/obsw_host", os.path.dirname(obsw_host.__file__)),
        ("mission", mission_dir),
    ):
        out.update(tree_files(root, prefix, skip=(state,)))
    return out


def tree_files(root, prefix, skip=()):
    """{prefix/relative path: path} of every regular file under ``root`` a package carries,
    but those under the folders ``skip``."""
    if not os.path.isdir(root):
        raise UserError("%s is not a folder" % root)
    skip = {os.path.realpath(x) for x in skip}
    out = {}
    for d, dirs, names in os.walk(root):
        dirs[:] = sorted(
            x
            for x in dirs
            if x not in _SKIP_DIRS and os.path.realpath(os.path.join(d, x)) not in skip
        )
        for name in sorted(names):
            if name.endswith(_SKIP_SUFFIXES):
                continue
            path = os.path.join(d, name)
            if not os.path.isfile(path):
                continue  # a socket or a pipe of a running process: not a file to carry
            rel = os.path.relpath(path, root).replace(os.sep, "/")
            out[prefix + "/" + rel] = path
    return out


def _sha256_file(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 16), b""):
            h.update(chunk)
    return h.hexdigest()


def base_manifest(path, public, mission, target):
    """The verified manifest of package ``path`` (the base of a delta)."""
    with open(path, "rb") as f:
        return Reader(f, verify, public, mission, target).manifest


def build(out, files, *, mission, version, key, target="obc", base=None, downgrade=False):
    """Write the package ``out`` of ``files`` ({package path: file path}, in the order they
    are carried), signed with
    ``key`` (an Ed25519 private key); ``base``: the manifest of the package it is a delta
    to; ``downgrade``: the package may replace a newer version on board (anti-rollback).
    Returns the manifest. The package is written whole or not at all."""
    if target not in TARGETS:
        raise UserError("target %r" % target, "one of %s" % ", ".join(TARGETS))
    tree = {p: _sha256_file(src) for p, src in files.items()}
    carried = list(files)  # in the caller's order (the module's load order)
    if base is not None:
        carried = [p for p in carried if base["tree"].get(p) != tree[p]]
    manifest = {
        "format": 1,
        "mission": mission,
        "target": target,
        "version": version,
        "base": base["version"] if base is not None else None,
        "created": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "files": [
            {"path": p, "size": os.path.getsize(files[p]), "sha256": tree[p]} for p in carried
        ],
        "tree": tree,
    }
    if downgrade:
        manifest["downgrade"] = True
    body = canonical(manifest)
    part = out + ".part"
    with open(part, "wb") as f:
        f.write(header(body, key.sign(body)))
        for p in carried:
            with open(files[p], "rb") as src:
                while chunk := src.read(1 << 16):
                    f.write(chunk)
        f.flush()
        os.fsync(f.fileno())
    os.replace(part, out)
    return manifest


def describe(manifest):
    """One line: version, target, full or delta, files carried of the tree."""
    kind = "delta to %s" % manifest["base"] if manifest["base"] else "full"
    return "%s %s for %s (%s): %d of %d files" % (
        manifest["mission"], manifest["version"], manifest["target"], kind,
        len(manifest["files"]), len(manifest["tree"]))  # fmt: skip


def dump(manifest):
    return json.dumps(manifest, indent=2, sort_keys=True)
