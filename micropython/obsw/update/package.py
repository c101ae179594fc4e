"""Signed software update packages: the format, and reading one while checking everything.

A package (``.obsw``) is::

    b"OBSWPKG1" | u32 manifest length | manifest | 64-byte signature | the files' bytes

The manifest is UTF-8 JSON in canonical form (keys sorted, no spaces), signed with Ed25519
(the signature is over exactly the manifest's bytes), and holds::

    {"format": 1, "mission": NAME, "target": "obc" | "reconfig", "version": TEXT,
     "base": null or the version the package applies to, "created": ISO-8601 UTC,
     "files": [{"path": P, "size": N, "sha256": HEX}, ..],   the bytes carried, in order
     "tree": {P: HEX, ..},                                     every file of the result
     "downgrade": true}              optional: this package may replace a newer version

A full package carries every file of its tree; a delta (``base`` set) carries only the files
that differ from its base's, and the receiver takes the others from the base, each checked
against its hash in ``tree``. Paths are relative POSIX paths without ``..``.

``Reader(stream, verify, key, mission, target)`` reads the header, checks the signature with
``verify(key, signature, manifest_bytes)`` and the manifest's mission and target before a file
byte is read, then ``files(write)`` streams every file in chunks to ``write(path, chunk)`` (and
``write(path, None)`` at its end) and checks its size and SHA-256 as it goes. Anything wrong
raises a ``PackageError`` subclass whose ``code`` names it (the reason an event carries).
Sans-I/O: ``stream`` is anything with ``read(n)``.
"""

import hashlib
import json
import struct

from obsw import jsonsafe
from obsw.compat import const

MAGIC = b"OBSWPKG1"
FORMAT = const(1)
SIGNATURE_SIZE = const(64)
TARGETS = ("obc", "reconfig")
_MAX_MANIFEST = const(1 << 20)
_CHUNK = const(1024)
_MAX_DEPTH = const(8)  # a manifest nests 3 deep: object, "files" list, file object


class PackageError(ValueError):
    """A package that must not be installed; ``code`` names why (the reasons below)."""

    code = "bad_package"


class BadMagic(PackageError):
    code = "bad_magic"


class Truncated(PackageError):
    code = "truncated"


class BadManifest(PackageError):
    code = "bad_manifest"


class BadSignature(PackageError):
    code = "bad_signature"


class WrongMission(PackageError):
    code = "wrong_mission"


class WrongTarget(PackageError):
    code = "wrong_target"


class HashMismatch(PackageError):
    code = "hash_mismatch"


class BadPath(PackageError):
    code = "bad_path"


class Rollback(PackageError):
    """An older version than the one the OBC's floor allows, without a signed ``downgrade``."""

    code = "rollback"


REASONS = (
    "bad_package",
    "bad_magic",
    "truncated",
    "bad_manifest",
    "bad_signature",
    "wrong_mission",
    "wrong_target",
    "hash_mismatch",
    "bad_path",
    "rollback",
)


def version_key(text):
    """A sort key of a version text: dot-separated parts, each compared by its leading number
    and then by the rest ("1.10" > "1.9" > "1.9rc1" > "1"), so that any two versions order."""
    out = []
    for part in str(text).split("."):
        i = 0
        while i < len(part) and "0" <= part[i] <= "9":
            i += 1
        rest = part[i:]  # a suffix marks a pre-release: "9rc1" before "9"
        out.append((int(part[:i]) if i else -1, 0 if rest else 1, rest))
    return tuple(out)


def check_floor(manifest, floor):
    """Rollback unless ``manifest``'s version is ``floor`` or newer, or it allows a downgrade
    (a field of the signed manifest, so only the key's holder can allow one)."""
    if floor is None or manifest.get("downgrade") is True:
        return manifest
    if version_key(manifest["version"]) < version_key(floor):
        raise Rollback(
            "version %s is older than %s, the oldest this OBC takes (a package that may "
            "downgrade says so in its signed manifest)" % (manifest["version"], floor)
        )
    return manifest


def canonical(manifest):
    """The manifest's bytes as signed: JSON, keys sorted, no spaces, UTF-8 (the reader checks
    the bytes it received, never a serialization of its own)."""
    return _json(manifest).encode()


def _json(v):
    if isinstance(v, dict):
        return "{" + ",".join(json.dumps(k) + ":" + _json(v[k]) for k in sorted(v)) + "}"
    if isinstance(v, (list, tuple)):
        return "[" + ",".join(_json(x) for x in v) + "]"
    return json.dumps(v)


def check_path(path):
    """``path`` if it is a relative POSIX path inside the package's root, else BadPath."""
    if not isinstance(path, str) or not path or path[0] == "/" or "\\" in path or "\0" in path:
        raise BadPath("file path %r: not a relative POSIX path" % (path,))
    for part in path.split("/"):
        if part in ("", ".", ".."):
            raise BadPath("file path %r: empty, '.' or '..' part" % (path,))
    return path


def sha256_hex(data):
    return _hex(hashlib.sha256(data).digest())


def _hex(digest):
    return "".join("%02x" % b for b in digest)


def header(manifest_bytes, signature):
    """The bytes before the files: magic, length, manifest, signature."""
    if len(signature) != SIGNATURE_SIZE:
        raise ValueError("signature: %d bytes, Ed25519 has 64" % len(signature))
    return MAGIC + struct.pack(">I", len(manifest_bytes)) + manifest_bytes + signature


def check_manifest(m):
    """The manifest's fields and types, or BadManifest (paths: BadPath)."""
    if not isinstance(m, dict) or m.get("format") != FORMAT:
        raise BadManifest("manifest: not format %d" % FORMAT)
    for key in ("mission", "target", "version", "created"):
        if not isinstance(m.get(key), str) or not m[key]:
            raise BadManifest("manifest: %r missing or not text" % key)
    if "downgrade" in m and not isinstance(m["downgrade"], bool):
        raise BadManifest("manifest: 'downgrade' is neither true nor false")
    base = m.get("base")
    if base is not None and not isinstance(base, str):
        raise BadManifest("manifest: 'base' is neither null nor text")
    files = m.get("files")
    tree = m.get("tree")
    if not isinstance(files, list) or not isinstance(tree, dict):
        raise BadManifest("manifest: 'files' must be a list and 'tree' an object")
    for path, digest in tree.items():
        check_path(path)
        if not isinstance(digest, str) or len(digest) != 64:
            raise BadManifest("manifest: tree entry %s has no SHA-256" % path)
    seen = set()
    for f in files:
        if not isinstance(f, dict) or not isinstance(f.get("size"), int) or f["size"] < 0:
            raise BadManifest("manifest: a file entry without a size")
        path = check_path(f.get("path"))
        if path in seen or tree.get(path) != f.get("sha256"):
            raise BadManifest("manifest: file %s twice, or its hash is not the tree's" % path)
        seen.add(path)
    if base is None and len(seen) != len(tree):
        raise BadManifest("manifest: a full package must carry every file of its tree")
    return m


class Reader:
    """Reads and checks a package from ``stream`` (see the module text)."""

    def __init__(self, stream, verify, key, mission, target):
        self.stream = stream
        if self._read(len(MAGIC)) != MAGIC:
            raise BadMagic("not an obsw update package (no %r at its start)" % MAGIC)
        (n,) = struct.unpack(">I", self._read(4))
        if n > _MAX_MANIFEST:
            raise BadManifest("manifest of %d bytes: more than %d" % (n, _MAX_MANIFEST))
        self.manifest_bytes = self._read(n)
        self.signature = self._read(SIGNATURE_SIZE)
        if not verify(key, self.signature, self.manifest_bytes):
            raise BadSignature("the manifest's signature does not verify with the mission's key")
        try:
            m = jsonsafe.loads(self.manifest_bytes, _MAX_DEPTH)
        except ValueError as e:  # not JSON, not UTF-8, or nested deeper than a manifest is
            raise BadManifest("manifest: not JSON (%s)" % e) from None
        self.manifest = check_manifest(m)
        if m["mission"] != mission:
            raise WrongMission("package for mission %r, this is %r" % (m["mission"], mission))
        if m["target"] != target:
            raise WrongTarget("package for the %s, this is the %s" % (m["target"], target))

    def _read(self, n):
        data = self.stream.read(n)
        if data is None or len(data) != n:
            raise Truncated("package ends early: %d more bytes expected" % n)
        return data

    def files(self, write):
        """Stream every file to ``write(path, chunk)`` / ``write(path, None)``, checking
        sizes and hashes; nothing may follow the last file."""
        for f in self.manifest["files"]:
            path = f["path"]
            left = f["size"]
            h = hashlib.sha256()
            while left:
                chunk = self._read(min(left, _CHUNK))
                h.update(chunk)
                write(path, chunk)
                left -= len(chunk)
            if _hex(h.digest()) != f["sha256"]:
                raise HashMismatch("file %s: its SHA-256 is not the manifest's" % path)
            write(path, None)
        if self.stream.read(1):
            raise BadManifest("bytes after the last file")
