"""`obsw obc serve`: run the on-board PUS application process on UDP port 5000 + APID."""

import sys

from obsw_host.net import DEFAULT_HOST


def add_parser(sub):
    p = sub.add_parser("obc", help="on-board processes", description=__doc__)
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True
    x = s.add_parser("serve", help="serve the PUS application process until Ctrl-C")
    x.add_argument("--sdb", help="spacecraft database JSON (default: the sample database)")
    x.add_argument("--host", default=DEFAULT_HOST, help="address to bind (default %(default)s)")
    x.add_argument("--port", type=int, help="UDP port (default 5000 + APID)")
    x.add_argument("--apid", type=int, help="APID (default: the database's 'pus')")
    x.add_argument("--period", type=float, default=0.1, help="activity loop cycle, seconds")
    x.add_argument("--store", help="context store folder (service state survives restarts)")
    x.add_argument(
        "--no-sample", action="store_true", help="do not host the sample solar panel component"
    )
    x.set_defaults(func=serve)


def serve(args):
    from obsw import sdb as sdb_module
    from obsw.store import Store

    from obsw_host.pus.demo import SDB_PATH
    from obsw_host.pus.onboard import Onboard

    sdb = sdb_module.load(args.sdb or SDB_PATH)
    components = []
    if not args.no_sample:
        from obsw_host.solar_panel import SOLAR_PANEL, SolarPanel

        components.append((SOLAR_PANEL, SolarPanel()))
    onboard = Onboard(
        sdb,
        apid=args.apid,
        host=args.host,
        port=args.port,
        period=args.period,
        store=Store(args.store) if args.store else None,
        components=components,
    )
    print(
        "PUS application process APID %d serving on udp %s:%d (Ctrl-C stops)"
        % (onboard.apid, onboard.host, onboard.port),
        file=sys.stderr,
        flush=True,
    )
    try:
        onboard.serve()
    except KeyboardInterrupt:
        pass
    return 0
