"""`obsw yamcs`: XTCE from the spacecraft database, a Yamcs instance, and Yamcs next to the OBC.

Everything follows the mission (``--mission DIR``): the instance is named after it, and its
SCID, virtual channels, CFDP entities, APIDs and ports come from its files. ``run`` starts the
mission's PUS process and CFDP entity in-process, or with ``--obc HOST:PORT`` links Yamcs to an
``obsw obc serve`` that already runs.
"""

import json
import os
import shutil
import signal
import sys
import tempfile
import threading
import urllib.request

from obsw_host import ids as mission_ids
from obsw_host.errors import UserError


def add_parser(sub):
    p = sub.add_parser("yamcs", help="mission control with Yamcs", description=__doc__)
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True

    x = s.add_parser("xtce", help="print the XTCE mission database of a spacecraft database")
    x.add_argument("sdb", nargs="?", help="spacecraft database JSON (default: the mission's)")
    x.add_argument("--mission", metavar="DIR", help="mission folder or mission file")
    x.add_argument("-o", "--output", help="write to this file instead of standard output")
    x.set_defaults(func=xtce)

    x = s.add_parser("config", help="write a complete Yamcs instance (etc/, mdb/) in a folder")
    x.add_argument("dir", help="folder to write (created if needed)")
    _instance_options(x)
    x.set_defaults(func=config)

    x = s.add_parser("check", help="Yamcs' own validation (--check) of an instance folder")
    x.add_argument("dir")
    x.set_defaults(func=check)

    x = s.add_parser("run", help="run Yamcs next to the mission's spacecraft until Ctrl-C")
    x.add_argument("--dir", help="instance folder (default: a new temporary folder)")
    _instance_options(x)
    x.add_argument(
        "--obc",
        metavar="HOST:PORT",
        help="operate a running `obsw obc serve` (its PUS process) instead of starting one "
        "(packets mode)",
    )
    x.add_argument("--files", help="the on-board CFDP filestore (default: DIR/sat)")
    x.add_argument("--seconds", type=float, help="stop after this many seconds")
    x.set_defaults(func=run_in_temp)


def _instance_options(x):
    from obsw_host.ports import YAMCS_LINKS

    mission_ids.add_arguments(x)
    x.add_argument(
        "--mode",
        choices=("packets", "frames"),
        default="packets",
        help="PUS packets over TCP, or TC/TM frames with CLTUs and COP-1 over UDP",
    )
    x.add_argument("--http-port", type=int, help="web and API port (default: the mission's)")
    x.add_argument(
        "--keys",
        help="SDLS key file (frames mode): TC and TM protected with Yamcs' AES-256-GCM SDLS",
    )
    for name in YAMCS_LINKS:
        x.add_argument(
            "--%s-port" % name.replace("_", "-"),
            type=int,
            help="ground port of the %s link (default: the mission's)" % name,
        )


def _ports(args, ids):
    """Yamcs' link ports: the command line's, else the mission's (``obsw_host.ports``)."""
    ports = ids.ports.yamcs()
    for name in ports:
        given = getattr(args, "%s_port" % name)
        if given is not None:
            ports[name] = given
    return ports


def _http_port(args, ids):
    return args.http_port if args.http_port is not None else ids.ports.yamcs_http


def xtce(args):
    from obsw_host.yamcs import database
    from obsw_host.yamcs.xtce import generate

    text = generate(database.from_ids(mission_ids.MissionIds.locate(args.mission, args.sdb)))
    if args.output:
        with open(args.output, "w") as f:
            f.write(text)
    else:
        sys.stdout.write(text)
    return 0


def _write(folder, ids, args, ports=None):
    """Write the mission's Yamcs instance into ``folder``; returns (instance name, MDB path)."""
    from obsw.frames.sdls_keys import KeyFileError

    from obsw_host.yamcs import database
    from obsw_host.yamcs.instance import instance_name, write_instance

    name = instance_name(ids.name)
    try:
        mdb = write_instance(
            folder,
            database.from_ids(ids),
            args.mode,
            ports=ports or _ports(args, ids),
            http_port=_http_port(args, ids),
            ids=ids,
            name=name,
            keys=getattr(args, "keys", None),
        )
    except KeyFileError as e:
        raise UserError(str(e)) from None
    return name, mdb


def config(args):
    ids = mission_ids.from_args(args)
    name, mdb = _write(args.dir, ids, args)
    print(
        "Yamcs instance %r (%s links) in %s, mission database %s"
        % (name, args.mode, args.dir, mdb)
    )
    if args.keys and args.mode == "frames":
        print(
            "SDLS: AES-256-GCM on TC and TM from %s, keys in %s/etc/sdls" % (args.keys, args.dir)
        )
    return 0


def check(args):
    from obsw_host.yamcs import server

    problem = server.missing()
    if problem:
        print(problem, file=sys.stderr)
        return 1
    ok, output = server.check(os.path.abspath(args.dir))
    if not ok:
        sys.stderr.write(output)
        return 1
    print("Yamcs accepts the configuration and mission database in %s" % args.dir)
    return 0


def _initialize_cop1(url, instance, vc):
    """Initiate AD service with a CLCW check, as an operator does once the link is up."""
    body = json.dumps({"type": "WITH_CLCW_CHECK", "clcwCheckInitializeTimeout": 10000}).encode()
    req = urllib.request.Request(
        "%s/api/cop1/%s/tc_frames.vc%d:initialize" % (url, instance, vc),
        data=body,
        headers={"Content-Type": "application/json"},
        method="POST",
    )
    urllib.request.urlopen(req, timeout=10).close()


def run(args):
    from obsw_host.yamcs import server

    problem = server.missing()
    if problem:
        print(problem, file=sys.stderr)
        return 1
    ids = mission_ids.from_args(args)
    if args.obc and args.mode != "packets":
        raise UserError(
            "--obc works with --mode packets",
            expected="the packet links (the OBC's UARTs carry its frames)",
        )
    folder = os.path.abspath(args.dir or tempfile.mkdtemp(prefix="obsw-yamcs-"))
    ports = _ports(args, ids)
    if args.obc:
        from obsw_host.yamcs.obc_link import ObcLink, parse_address

        try:
            obc = parse_address(args.obc)
        except ValueError as e:
            raise UserError(str(e)) from None
        sat = ObcLink(ids, obc, ports)
        what = "the OBC at %s:%d" % obc
    else:
        from obsw_host.yamcs.spacecraft import SampleSpacecraft

        sat = SampleSpacecraft(
            ids.sdb_path,
            args.files or os.path.join(folder, "sat"),
            args.mode,
            tm_frames_port=ports["tm_frames"],
            ports=ports,
            ids=ids,
            keys=args.keys if args.mode == "frames" else None,
        )
        what = "the spacecraft of %s" % (ids.mission_file or ids.sdb_file)
    try:
        name, _ = _write(folder, ids, args, ports)
        sat.start()
        yamcs = server.Yamcs(folder, _http_port(args, ids), instance=name)
        yamcs.start(timeout=120)
        try:
            if args.mode == "frames":
                _initialize_cop1(yamcs.url, name, ids.tc_vc)
            print(
                "Yamcs %s on %s, instance %r, %s links to %s; files in %s (Ctrl-C stops)"
                % (server.VERSION, yamcs.url, name, args.mode, what, folder),
                file=sys.stderr,
                flush=True,
            )
            threading.Event().wait(args.seconds)
        except KeyboardInterrupt:
            pass
        finally:
            yamcs.stop()
    finally:
        sat.close()
    return 0


def run_in_temp(args):
    """``run``; without ``--dir`` its instance (Yamcs' data, some MB) lives in a new temporary
    folder that is removed when Yamcs stops, by Ctrl-C, SIGTERM, ``--seconds`` or an error."""
    signal.signal(signal.SIGTERM, _interrupt)
    mission_ids.from_args(args)  # no mission: its one line before anything starts
    print("starting Yamcs (Java; up to a minute) ...", file=sys.stderr, flush=True)
    if args.dir:
        return run(args)
    args.dir = tempfile.mkdtemp(prefix="obsw-yamcs-")
    try:
        return run(args)
    finally:
        shutil.rmtree(args.dir, ignore_errors=True)


def _interrupt(signum, frame):
    raise KeyboardInterrupt
