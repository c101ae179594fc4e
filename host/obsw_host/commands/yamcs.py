"""`obsw yamcs`: XTCE from the spacecraft database, a Yamcs instance, and Yamcs next to the OBC."""

import json
import os
import shutil
import signal
import sys
import tempfile
import threading
import urllib.request


def add_parser(sub):
    p = sub.add_parser("yamcs", help="mission control with Yamcs", description=__doc__)
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True

    x = s.add_parser("xtce", help="print the XTCE mission database of a spacecraft database")
    x.add_argument("sdb", nargs="?", help="spacecraft database JSON (default: the sample)")
    x.add_argument("-o", "--output", help="write to this file instead of standard output")
    x.set_defaults(func=xtce)

    x = s.add_parser("config", help="write a complete Yamcs instance (etc/, mdb/) in a folder")
    x.add_argument("dir", help="folder to write (created if needed)")
    _instance_options(x)
    x.set_defaults(func=config)

    x = s.add_parser("check", help="Yamcs' own validation (--check) of an instance folder")
    x.add_argument("dir")
    x.set_defaults(func=check)

    x = s.add_parser("run", help="run Yamcs next to the sample spacecraft until Ctrl-C")
    x.add_argument("--dir", help="instance folder (default: a new temporary folder)")
    _instance_options(x)
    x.add_argument("--files", help="the on-board CFDP filestore (default: DIR/sat)")
    x.add_argument("--seconds", type=float, help="stop after this many seconds")
    x.set_defaults(func=run_in_temp)


def _instance_options(x):
    from obsw_host.yamcs.instance import HTTP_PORT, PORTS

    x.add_argument("--sdb", help="spacecraft database JSON (default: the sample)")
    x.add_argument(
        "--mode",
        choices=("packets", "frames"),
        default="packets",
        help="PUS packets over TCP, or TC/TM frames with CLTUs and COP-1 over UDP",
    )
    x.add_argument("--http-port", type=int, default=HTTP_PORT, help="web and API port")
    for name, port in PORTS.items():
        x.add_argument(
            "--%s-port" % name.replace("_", "-"),
            type=int,
            default=port,
            help="ground port of the %s link (default %%(default)s)" % name,
        )


def _ports(args):
    from obsw_host.yamcs.instance import PORTS

    return {name: getattr(args, "%s_port" % name) for name in PORTS}


def xtce(args):
    from obsw_host.yamcs import database
    from obsw_host.yamcs.xtce import generate

    text = generate(database.load(args.sdb))
    if args.output:
        with open(args.output, "w") as f:
            f.write(text)
    else:
        sys.stdout.write(text)
    return 0


def config(args):
    from obsw_host.yamcs import database
    from obsw_host.yamcs.instance import write_instance

    mdb = write_instance(
        args.dir,
        database.load(args.sdb),
        args.mode,
        ports=_ports(args),
        http_port=args.http_port,
    )
    print(
        "Yamcs instance 'obsw' (%s links) in %s, mission database %s" % (args.mode, args.dir, mdb)
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


def _initialize_cop1(url, link="tc_frames.vc0"):
    """Initiate AD service with a CLCW check, as an operator does once the link is up."""
    body = json.dumps({"type": "WITH_CLCW_CHECK", "clcwCheckInitializeTimeout": 10000}).encode()
    req = urllib.request.Request(
        "%s/api/cop1/obsw/%s:initialize" % (url, link),
        data=body,
        headers={"Content-Type": "application/json"},
        method="POST",
    )
    urllib.request.urlopen(req, timeout=10).close()


def run(args):
    from obsw_host.sample import SDB_PATH
    from obsw_host.yamcs import database, server
    from obsw_host.yamcs.instance import write_instance
    from obsw_host.yamcs.spacecraft import SampleSpacecraft

    problem = server.missing()
    if problem:
        print(problem, file=sys.stderr)
        return 1
    folder = os.path.abspath(args.dir or tempfile.mkdtemp(prefix="obsw-yamcs-"))
    sdb_path = args.sdb or SDB_PATH
    ports = _ports(args)
    sat = SampleSpacecraft(
        sdb_path,
        args.files or os.path.join(folder, "sat"),
        args.mode,
        tm_frames_port=ports["tm_frames"],
        ports=ports,
    )
    try:
        write_instance(folder, database.load(sdb_path), args.mode, ports, args.http_port)
        sat.start()
        yamcs = server.Yamcs(folder, args.http_port)
        yamcs.start(timeout=120)
        try:
            if args.mode == "frames":
                _initialize_cop1(yamcs.url)
            print(
                "Yamcs %s on %s, instance 'obsw', %s links to the sample spacecraft; files in %s "
                "(Ctrl-C stops)" % (server.VERSION, yamcs.url, args.mode, folder),
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
    if args.dir:
        return run(args)
    args.dir = tempfile.mkdtemp(prefix="obsw-yamcs-")
    try:
        return run(args)
    finally:
        shutil.rmtree(args.dir, ignore_errors=True)


def _interrupt(signum, frame):
    raise KeyboardInterrupt
