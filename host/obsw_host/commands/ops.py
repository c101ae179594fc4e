"""`obsw ops passes|plan|uplink`: operations across passes, from the mission's orbit and stations.

`passes --mission M --days N` lists every pass of the coming days over the mission's stations:
AOS, culmination and LOS (UTC), maximum elevation, and what the pass can carry at the station's
rates. `plan --mission M` turns passes into service 11 time-tagged commands (docs/passes.md).
`uplink --mission M --days N` sends the predicted passes to the spacecraft as its onboard pass
table (TC[8,1] ``Passes.load``; at most 64 windows, passes that overlap merged): the OBC's
store-and-forward then starts its dumps at each AOS.
"""

import datetime
import json

from obsw_host.errors import UserError
from obsw_host.net import DEFAULT_HOST


def add_parser(sub):
    p = sub.add_parser("ops", help="operations across passes: pass prediction, pass plans",
                       description=__doc__)  # fmt: skip
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True
    ps = s.add_parser("passes", help="predict the passes over the mission's stations")
    _window(ps)
    ps.set_defaults(func=passes_cmd)
    pl = s.add_parser("plan", help="service 11 commands for the passes (transmitter, dump)")
    _window(pl)
    pl.add_argument("--lead", type=float, default=60.0, help="seconds before AOS to switch "
                    "the transmitter on (default 60)")  # fmt: skip
    pl.add_argument("--lag", type=float, default=30.0, help="seconds after LOS to switch it "
                    "off (default 30)")  # fmt: skip
    pl.add_argument("--report", metavar="FILE",
                    help="an onboard schedule report (JSON of `obsw ground` service 11 detail "
                    "report): check it against the plan instead of printing the plan")  # fmt: skip
    pl.set_defaults(func=plan_cmd)
    up = s.add_parser("uplink", help="send the predicted passes as the onboard pass table")
    _window(up)
    up.add_argument("--host", default=DEFAULT_HOST, help="on-board host (default %(default)s)")
    up.add_argument("--port", type=int, help="on-board UDP port (default: the mission's)")
    up.add_argument("--apid", type=int, help="on-board APID (default: the database's 'pus')")
    up.add_argument("--timeout", type=float, default=5.0, help="seconds to wait for the "
                    "completion report (default 5)")  # fmt: skip
    up.add_argument("-v", "--verbose", action="store_true", help="print every packet")
    up.set_defaults(func=uplink_cmd)


def _window(p):
    p.add_argument("--mission", help="mission folder or file (default: $OBSW_MISSION, or a "
                   "mission.json here or above)")  # fmt: skip
    p.add_argument("--days", type=float, default=1.0, help="how many days ahead (default 1)")
    p.add_argument("--start", help="UTC start, YYYY-MM-DDTHH:MM:SSZ (default: now)")
    p.add_argument("--station", action="append", help="only this station (repeatable)")


def predict(args):
    """The mission's ``Predictor`` and the passes of the window ``args`` names."""
    from obsw_host.mission.check import load
    from obsw_host.ops.passes import from_mission
    from obsw_host.ops.tle import TleError, parse_time

    m = load(args.mission)
    doc = m.config.doc
    if "orbit" not in doc or "stations" not in doc:
        raise UserError(
            "%s has no orbit or no stations" % m.path,
            expected='"orbit" (tle, epoch) and "stations" in the mission file',
        )
    pred = from_mission(doc)
    stations = pred.stations
    if args.station:
        names = [s.name for s in stations]
        for name in args.station:
            if name not in names:
                raise UserError("no station %r" % name, expected="one of %s" % ", ".join(names))
        stations = [s for s in stations if s.name in args.station]
    if args.days <= 0:
        raise UserError("--days %s" % args.days, expected="a positive number of days")
    try:
        start = parse_time(args.start) if args.start else datetime.datetime.now(
            datetime.timezone.utc)  # fmt: skip
    except TleError as e:
        raise UserError("--start: %s" % e) from None
    t0 = start.timestamp()
    return pred, pred.passes(t0, t0 + args.days * 86400.0, stations)


def passes_cmd(args):
    _, passes = predict(args)
    rows = [p.to_dict() for p in passes]
    if args.json:
        print(json.dumps({"passes": rows}, indent=2))
        return 0
    head = ("station", "AOS (UTC)", "LOS (UTC)", "dur s", "max el", "down octets", "up octets")
    print("%-10s %-24s %-24s %7s %6s %11s %10s" % head)
    for r in rows:
        print("%-10s %-24s %-24s %7.0f %6.1f %11d %10d" % (
            r["station"], r["aos"], r["los"], r["duration"], r["max_elevation"],
            r["downlink_octets"], r["uplink_octets"]))  # fmt: skip
    total = sum(r["downlink_octets"] for r in rows)
    print("%d passes, %d octets down in all" % (len(rows), total))
    return 0


def plan_cmd(args):
    from obsw_host.ops import plan

    _, passes = predict(args)
    steps = plan.plan(passes, lead=args.lead, lag=args.lag)
    if args.report:
        from obsw_host.errors import read_json

        report = read_json(args.report, "schedule report")
        problems = plan.check_schedule(steps, report)
        if args.json:
            print(json.dumps({"ok": not problems, "problems": problems}, indent=2))
        else:
            for p in problems:
                print(p)
            print("schedule %s: %d planned commands, %d problems" % (
                "ok" if not problems else "differs", len(steps), len(problems)))  # fmt: skip
        return 2 if problems else 0
    if args.json:
        print(json.dumps({"plan": [s.to_dict() for s in steps]}, indent=2))
        return 0
    for s in steps:
        print(s)
    print("%d commands for %d passes" % (len(steps), len(passes)))
    return 0


def uplink_cmd(args):
    """TC[8,1] Passes.load with the passes of the window: 0 when the OBC completed it."""
    from obsw_host.commands import session
    from obsw_host.ops.pass_table import LIMIT, table, windows

    _, passes = predict(args)
    ws = windows(passes)
    if not args.json:
        more = len(windows(passes, limit=10**6)) - len(ws)
        print("%d passes, %d windows in the table%s" % (len(passes), len(ws), (
            " (%d more beyond the table's %d: uplink again later)" % (more, LIMIT)
            if more else "")))  # fmt: skip
    return session.run(args, lambda g: g.perform("Passes.load", table=table(passes)))
