"""`obsw yamcs`: XTCE from the spacecraft database, a Yamcs instance, and Yamcs next to the OBC.

Everything follows the mission (``--mission DIR``): the instance is named after it, and its
SCID, virtual channels, CFDP entities, APIDs and ports come from its files. ``run`` starts the
mission's PUS process and CFDP entity in-process, or with ``--obc HOST:PORT`` links Yamcs to an
``obsw obc serve`` that already runs. ``--mission`` given several times operates several
spacecraft from one Yamcs server, one instance each (``obsw_host.yamcs.fleet``): ``config``
writes them all, ``run`` links each to its own OBC (``--obc`` once per mission, in the same
order) or starts each mission's PUS process; missions that share an instance name, a
spacecraft id or a port are refused in one line before anything starts.
"""

import argparse
import json
import os
import shutil
import signal
import sys
import tempfile
import threading
import time
import urllib.request

from obsw_host.errors import UserError
from obsw_host.mission import ids as mission_ids


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
        action="append",
        help="operate a running `obsw obc serve` (its PUS process) instead of starting one "
        "(packets mode); once per --mission, in the same order",
    )
    x.add_argument(
        "--listen",
        metavar="ADDRESS",
        default="127.0.0.1",
        help="with --obc: the address where the OBCs' TM and CFDP PDUs arrive, this machine's "
        "on their network when they run elsewhere (default 127.0.0.1)",
    )
    x.add_argument("--files", help="the on-board CFDP filestore (default: DIR/sat)")
    x.add_argument("--seconds", type=float, help="stop after this many seconds")
    x.set_defaults(func=run_in_temp)


def _instance_options(x):
    from obsw_host.mission.ports import YAMCS_LINKS

    x.add_argument(
        "--mission",
        metavar="DIR",
        action="append",
        default=argparse.SUPPRESS,
        help="mission folder (with mission.json) or mission file; repeat it to operate several "
        "spacecraft, one Yamcs instance each (default: $OBSW_MISSION, else the nearest "
        "mission.json from here up)",
    )
    x.add_argument(
        "--sdb",
        default=argparse.SUPPRESS,
        help="spacecraft database JSON (overrides the mission's)",
    )
    x.add_argument(
        "--mode",
        choices=("packets", "frames"),
        default="packets",
        help="PUS packets over TCP, or TC/TM frames with CLTUs and COP-1 over UDP",
    )
    x.add_argument("--http-port", type=int, help="web and API port (default: the mission's)")
    x.add_argument(
        "--http-address",
        default="127.0.0.1",
        help="this machine's address where the web interface and API listen, for operators on "
        "other machines (default 127.0.0.1)",
    )
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


def _missions(args):
    """The ``MissionIds`` of every ``--mission`` (one: the default mission); with several, the
    options that name one mission's ports or keys are refused."""
    given = getattr(args, "mission", None) or [None]
    if len(given) == 1:
        return [mission_ids.MissionIds.locate(given[0], getattr(args, "sdb", None))]
    from obsw_host.mission.ports import YAMCS_LINKS

    one = ["sdb", "keys"] + ["%s_port" % name for name in YAMCS_LINKS]
    for name in one:
        if getattr(args, name, None) is not None:
            raise UserError(
                "--%s with %d missions" % (name.replace("_", "-"), len(given)),
                expected='each mission\'s own in its mission folder (mission.json "ports", '
                "its spacecraft database)",
            )
    return [mission_ids.MissionIds.locate(m) for m in given]


def _ports(args, ids):
    """Yamcs' link ports: the command line's, else the mission's (``obsw_host.mission.ports``)."""
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
            http_address=args.http_address,
        )
    except KeyFileError as e:
        raise UserError(str(e)) from None
    return name, mdb


def _write_fleet(folder, missions, args):
    """Write one Yamcs server with an instance per mission into ``folder`` once the missions
    are known to fit side by side; returns the instance names."""
    from obsw_host.yamcs import database, fleet
    from obsw_host.yamcs.instance import Member, instance_name, write_fleet

    http = _http_port(args, missions[0])
    fleet.check(missions, http)
    members = [
        Member(instance_name(ids.name), database.from_ids(ids), args.mode, None, ids)
        for ids in missions
    ]
    write_fleet(folder, members, http, args.http_address)
    return [m.name for m in members]


def config(args):
    missions = _missions(args)
    if len(missions) > 1:
        names = _write_fleet(args.dir, missions, args)
        print(
            "Yamcs server with %d instances (%s links) in %s: %s"
            % (len(names), args.mode, args.dir, ", ".join(names))
        )
        for ids, name in zip(missions, names):
            print(
                "  %s: spacecraft id %s, links on ports %s, mission database mdb/%s.xml"
                % (name, ids.scid, _link_ports(ids, args.mode), name)
            )
        return 0
    ids = missions[0]
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


def _link_ports(ids, mode):
    links = ("pus", "cfdp") if mode == "packets" else ("cltu", "tm_frames")
    ports = ids.ports.yamcs()
    return ", ".join("%s %d" % (link, ports[link]) for link in links)


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


def _spacecraft(args, ids, folder, ports, obc, several):
    """The link to mission ``ids``'s spacecraft: a gateway to its running OBC at ``obc``, or
    its PUS process and CFDP entity in this process; returns (link, what it is)."""
    if obc:
        from obsw_host.yamcs.obc_link import ObcLink, parse_address

        try:
            address = parse_address(obc)
        except ValueError as e:
            raise UserError(str(e)) from None
        return ObcLink(ids, address, ports, args.listen), "the OBC at %s:%d" % address
    from obsw_host.yamcs.spacecraft import SampleSpacecraft

    files = args.files or os.path.join(folder, "sat")
    if several:  # each spacecraft its own filestore
        files = os.path.join(files, ids.name)
    sat = SampleSpacecraft(
        ids.sdb_path,
        files,
        args.mode,
        tm_frames_port=ports["tm_frames"],
        ports=ports,
        ids=ids,
        keys=args.keys if args.mode == "frames" else None,
    )
    return sat, "the spacecraft of %s" % (ids.mission_file or ids.sdb_file)


def _wait_running(yamcs, names, timeout=60.0):
    """Wait until every instance runs (Yamcs starts them together; the first is waited for
    by ``Yamcs.start``)."""
    end = time.monotonic() + timeout
    first = yamcs.instance
    try:
        for name in names:
            yamcs.instance = name
            while yamcs.state() != "RUNNING":
                if time.monotonic() > end:
                    raise TimeoutError(
                        "Yamcs instance %s did not start:\n%s" % (name, yamcs.tail())
                    )
                time.sleep(0.2)  # polling an external process's HTTP API
    finally:
        yamcs.instance = first


def _preflight(args):
    """``run``'s missions and OBC addresses, or its one-line refusal, before anything starts."""
    missions = _missions(args)
    obcs = args.obc or []
    if obcs and args.mode != "packets":
        raise UserError(
            "--obc works with --mode packets",
            expected="the packet links (the OBC's UARTs carry its frames)",
        )
    if obcs and len(obcs) != len(missions):
        raise UserError(
            "%d --obc for %d --mission" % (len(obcs), len(missions)),
            expected="one --obc HOST:PORT per mission, in the same order (or none)",
        )
    if len(set(obcs)) != len(obcs):
        raise UserError("--obc %s given twice" % [a for a in obcs if obcs.count(a) > 1][0],
                        expected="each mission's own OBC")  # fmt: skip
    if len(missions) > 1:
        from obsw_host.yamcs import fleet

        fleet.check(missions, _http_port(args, missions[0]))
    return missions, obcs


def run(args):
    from obsw_host.yamcs import server

    problem = server.missing()
    if problem:
        print(problem, file=sys.stderr)
        return 1
    missions, obcs = _preflight(args)
    several = len(missions) > 1
    folder = os.path.abspath(args.dir or tempfile.mkdtemp(prefix="obsw-yamcs-"))
    if several:
        names = _write_fleet(folder, missions, args)
        all_ports = [ids.ports.yamcs() for ids in missions]
    else:
        all_ports = [_ports(args, missions[0])]
    sats = []
    try:
        whats = []
        for i, ids in enumerate(missions):
            sat, what = _spacecraft(
                args, ids, folder, all_ports[i], obcs[i] if obcs else None, several
            )
            sats.append(sat)
            whats.append(what)
        if not several:
            names = [_write(folder, missions[0], args, all_ports[0])[0]]
        for sat in sats:
            sat.start()
        yamcs = server.Yamcs(
            folder, _http_port(args, missions[0]), instance=names[0], address=args.http_address
        )
        yamcs.start(timeout=120)
        try:
            _wait_running(yamcs, names[1:])
            if args.mode == "frames":
                for ids, name in zip(missions, names):
                    _initialize_cop1(yamcs.url, name, ids.tc_vc)
            if several:
                print(
                    "Yamcs %s on %s, %d instances, %s links: %s; files in %s (Ctrl-C stops)"
                    % (server.VERSION, yamcs.url, len(names), args.mode,
                       ", ".join("%r to %s" % nw for nw in zip(names, whats)), folder),
                    file=sys.stderr,
                    flush=True,
                )  # fmt: skip
            else:
                print(
                    "Yamcs %s on %s, instance %r, %s links to %s; files in %s (Ctrl-C stops)"
                    % (server.VERSION, yamcs.url, names[0], args.mode, whats[0], folder),
                    file=sys.stderr,
                    flush=True,
                )
            threading.Event().wait(args.seconds)
        except KeyboardInterrupt:
            pass
        finally:
            yamcs.stop()
    finally:
        for sat in sats:
            sat.close()
    return 0


def run_in_temp(args):
    """``run``; without ``--dir`` its instance (Yamcs' data, some MB) lives in a new temporary
    folder that is removed when Yamcs stops, by Ctrl-C, SIGTERM, ``--seconds`` or an error."""
    signal.signal(signal.SIGTERM, _interrupt)
    _preflight(args)  # no mission, missions that clash, ...: one line before anything starts
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
