"""`obsw update`: signed software updates of the OBC, from the ground.

    obsw update keygen ~/keys/update.key        Ed25519 pair; put update.key.pub in the mission
    obsw update build 1.1 -o v1.1.obsw --key ~/keys/update.key [--base v1.0.obsw]
    obsw update show v1.1.obsw                  its manifest; its signature and files checked
    obsw update push v1.1.obsw                  CFDP class 2 to the OBC, then stage it there
    obsw update status                          the version running, staged, on trial
    obsw update activate                        the staged version on trial: restart from it
    obsw update rollback                        end the trial, or go back to the version before

``build`` packs the ``obsw`` and ``obsw_host`` packages as installed here and the mission
folder (``--mission``), signed; with ``--base`` an earlier package, only what changed.
``push`` puts the package into the onboard filestore's ``update/`` folder and sends
``Software.stage`` (service 8), which verifies it there; ``activate``, ``rollback`` and
``status`` are service 8 and 20 requests. Their results are service 1 reports and the
``Software`` events (docs/update.md).
"""

import argparse
import os

from obsw_host.errors import UserError
from obsw_host.mission import ids as mission_ids
from obsw_host.net import DEFAULT_HOST

STATUS = ("Software.version", "Software.slot", "Software.pending", "Software.trial_starts")


def add_parser(sub):
    p = sub.add_parser(
        "update",
        help="signed software updates of the OBC",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True
    k = s.add_parser("keygen", help="make the Ed25519 key pair that signs packages")
    k.add_argument("private", help="the private key file to write (outside any repository)")
    k.set_defaults(func=keygen)
    b = s.add_parser("build", help="make a signed package of the OBC software")
    b.add_argument("version", help="the package's version, e.g. 1.1")
    b.add_argument("-o", "--out", required=True, help="the package file to write")
    b.add_argument("--key", required=True, help="the private key (obsw update keygen)")
    b.add_argument("--base", help="an earlier package of the mission: make a delta to it")
    b.add_argument("--downgrade", action="store_true",
                   help="the package may replace a newer version on board (signed in its "
                   "manifest; without it the OBC refuses an older version)")  # fmt: skip
    b.add_argument("--target", choices=("obc", "reconfig"), default="obc",
                   help="the OBC's software (default), or the reconfiguration module's "
                   "application (compiled, for obsw board update)")  # fmt: skip
    b.add_argument("--module", action="append", default=[],
                   help="reconfig: a changed module of the image, e.g. obsw/reconfig/app.py "
                   "(repeatable: a module after those it imports)")  # fmt: skip
    b.add_argument("--march", default="armv7emsp",
                   help="reconfig: mpy-cross -march (default %(default)s: Pyboard)")  # fmt: skip
    mission_ids.add_arguments(b)
    b.set_defaults(func=build)
    w = s.add_parser("show", help="a package's manifest, its signature checked")
    w.add_argument("package")
    mission_ids.add_arguments(w)
    w.set_defaults(func=show)
    for name, func, text in (
        ("push", push, "upload a package by CFDP and stage it on the OBC"),
        ("status", status, "the versions running and staged"),
        ("activate", activate, "run the staged version on trial"),
        ("rollback", rollback, "end the trial, or go back to the version before"),
    ):
        x = s.add_parser(name, help=text)
        if name == "push":
            x.add_argument("package")
            x.add_argument("--cfdp-timeout", type=float, default=120.0,
                           help="seconds the upload may take (default %(default)s)")  # fmt: skip
        mission_ids.add_arguments(x)
        x.add_argument("--host", default=DEFAULT_HOST, help="the OBC's host")
        x.add_argument("--port", type=int, help=argparse.SUPPRESS)
        x.add_argument("--apid", type=int, help=argparse.SUPPRESS)
        x.add_argument("--timeout", type=float, default=10.0, help="seconds per request")
        x.add_argument("-v", "--verbose", action="store_true", help="print every packet")
        x.add_argument("--log", metavar="FILE", default=os.environ.get("OBSW_SESSION_LOG"),
                       help="append every TC and TM to this session log")  # fmt: skip
        x.set_defaults(func=func, raw=False)


def _mission(args):
    """(MissionIds, the mission folder, its update public key or None)."""
    from obsw_host.mission import defaults
    from obsw_host.update.build import load_public

    ids = mission_ids.from_args(args)
    if ids.config is None:
        raise UserError("no mission: give --mission DIR")
    folder = os.path.dirname(os.path.abspath(ids.config.path))
    key = defaults.section(ids.config, "update")["public_key"]
    return ids, folder, load_public(os.path.join(folder, key)) if key else None


def keygen(args):
    from obsw_host.update.build import keygen as make

    public = make(args.private)
    print("wrote %s (secret: keep it off the spacecraft and out of repositories)" % args.private)
    print("wrote %s: copy it into the mission folder and name it in mission.json's"
          ' "update": {"public_key": ...}' % public)  # fmt: skip
    return 0


def _open(path, key, ids, whole=False):
    """The manifest of package ``path``, its signature checked (either target); ``whole``:
    every file's size and hash checked too, and nothing after the last."""
    from obsw.update.package import Reader, WrongTarget
    from obsw.update.signature import verify

    def read(target):
        with open(path, "rb") as f:
            reader = Reader(f, verify, key, ids.config.name, target)
            if whole:
                reader.files(lambda p, chunk: None)
            return reader.manifest

    try:
        return read("obc")
    except WrongTarget:
        return read("reconfig")


def build(args):
    from obsw_host.update import build as b

    ids, folder, public = _mission(args)
    key = b.load_private(args.key)
    if public is not None and b.public_hex(key) != public.hex():
        raise UserError("%s is not the key of the mission's update.public_key" % args.key)
    if args.target == "reconfig":
        if args.base:
            raise UserError("--base: the reconfiguration module takes full packages only")
        return _build_reconfig(args, ids, key)
    base = _open(args.base, public or bytes.fromhex(b.public_hex(key)), ids) if args.base else None
    manifest = b.build(args.out, b.sources(folder, ids.config.state), mission=ids.config.name,
                       version=args.version, key=key, base=base,
                       downgrade=args.downgrade)  # fmt: skip
    print("%s: %s, %d bytes" % (args.out, b.describe(manifest), os.path.getsize(args.out)))
    return 0


def _build_reconfig(args, ids, key):
    import tempfile

    from obsw_host import board
    from obsw_host.update import build as b

    if not args.module:
        raise UserError("--target reconfig needs the modules that changed", "--module PATH")
    with tempfile.TemporaryDirectory(prefix="obsw-update-") as tmp:
        try:
            files = board.compile_modules(tmp, args.march, args.module)
        except board.BoardError as e:
            raise UserError(str(e)) from None
        manifest = b.build(args.out, files, mission=ids.config.name, version=args.version,
                           key=key, target="reconfig")  # fmt: skip
    print("%s: %s, %d bytes (%s)" % (args.out, b.describe(manifest), os.path.getsize(args.out),
                                     args.march))  # fmt: skip
    return 0


def show(args):
    from obsw_host.update.build import describe, dump

    ids, _, public = _mission(args)
    if public is None:
        raise UserError("the mission names no update.public_key to check the package with")
    from obsw.update.package import PackageError

    try:
        manifest = _open(args.package, public, ids, whole=True)
    except PackageError as e:
        raise UserError("%s: %s (%s)" % (args.package, e, e.code)) from None
    if args.json:
        print(dump(manifest))
    else:
        print("%s: %s, signature and every file good" % (args.package, describe(manifest)))
    return 0


def _ground_args(args):
    args.sdb = getattr(args, "sdb", None)
    return args


def push(args):
    from obsw_host.cfdp.client import CfdpClient
    from obsw_host.update.component import INBOX

    ids, _, _ = _mission(args)
    if not os.path.isfile(args.package):
        raise UserError("%s: no such package" % args.package)
    sat, ground = ids.cfdp_entities
    root, name = os.path.split(os.path.abspath(args.package))
    dest = "%s/%s" % (INBOX, name)
    peers = {sat: (args.host, ids.ports.cfdp)}
    with CfdpClient(ground, peers, root, apid=ids.apid("cfdp"), cls=2,
                    port=ids.ports.cfdp_ground, timeout=args.cfdp_timeout) as c:  # fmt: skip
        result = c.put(name, dest)
    print(result.line())
    if not result.delivered:
        return 1
    return _perform(args, "Software.stage", file=dest)


def _perform(args, name, **arguments):
    from obsw_host.commands import session

    return session.run(_ground_args(args), lambda g: g.perform(session.key(name), **arguments))


def status(args):
    from obsw_host.commands import session

    return session.run(_ground_args(args), lambda g: g.get_parameters(*STATUS))


def activate(args):
    return _perform(args, "Software.activate")


def rollback(args):
    return _perform(args, "Software.rollback")
