"""`obsw ground`: PUS requests from the ground to an on-board process, results decoded.

    obsw ground ping
    obsw ground hk report 1                 one-shot housekeeping report of structure 1
    obsw ground hk structures 1 2           structure reports
    obsw ground hk create 5 10 SolarPanel.angle pus.tm_sent
    obsw ground hk enable|disable|delete 5
    obsw ground hk interval 5 20
    obsw ground hk listen --seconds 3       periodic reports as they come
    obsw ground params get SolarPanel.speed
    obsw ground params set SolarPanel.speed=7.5
    obsw ground params definitions | define SolarPanel.speed 1 4096 [--object ID]
    obsw ground events disabled | enable NAME.. | disable NAME.. | listen
    obsw ground time rate 0 | listen
    obsw ground connection 10
    obsw ground function SolarPanel.set_angle angle=15          service 8
    obsw ground service mtq dipole x=0.1 y=0 z=0    a mission service (types 128..255)
    obsw ground schedule insert --in 10 function SolarPanel.set_angle angle=20
    obsw ground schedule insert --at 2030-01-01T00:00:00Z ping
    obsw ground schedule list | summary | shift 30 | delete 0:10:5 | enable | disable | reset
    obsw ground position insert 120 set SolarPanel.speed=2      service 22
    obsw ground position list
    obsw ground monitor [--log session.log] [--seconds N] [--count N]   live TM view
    obsw ground replay session.log          a session log, decoded again
    obsw ground list parameters|functions|events|hk|services    from the database
    obsw ground list obcps | files [REPOSITORY]         from the on-board process
    obsw ground monitor add 1 SolarPanel.speed 0.5 10 --high-event monitoring.speed_high
    obsw ground monitor list | out-of-limits | enable 1 | disable 1 | delete 1
    obsw ground fmon add 7 1 2 --failing 1 --event monitoring.speed_high
    obsw ground fmon list | status | enable 7 | disable 7 | protect 7 | unprotect 7 | delete 7
    obsw ground fmon enable-function | disable-function
    obsw ground action add monitoring.speed_high set SolarPanel.speed=5
    obsw ground action list | enable EVENT | disable EVENT | delete EVENT
    obsw ground sequence load warmup "0 ping" "2 function SolarPanel.set_angle angle=10"
    obsw ground sequence status | content warmup | activate warmup | abort warmup | unload warmup
    obsw ground memory dump|load|check|load-file|check-object|abort-dumps|scrub|protect ..
    obsw ground store copy|diag ..   obsw ground sequence file|load-file ..
    obsw ground position orbit N     (commands of services 6, 15, 21, 22: see their --help)

A request to schedule, sequence or run as an action is ``ping``, ``function NAME
[ARG=VALUE..]``, ``service NAME REQUEST [ARG=VALUE..]`` or ``set NAME=VALUE..``;
activities are named SOURCE:APID:SEQ.

Every ground client receives all TM the on-board process sends (events, verification,
housekeeping), whichever client's TC caused it. ``--log FILE`` appends every TC and TM of the
command (raw and decoded) to a session log. ``--json`` prints one JSON object per command (per
packet for ``monitor``) instead of text; ``-v`` shows every packet.

Parameter values are engineering values (calibrated, with their unit, or an enumeration's
label; limits of ``monitor add`` too); ``--raw`` shows and takes raw values instead. A value
outside a parameter's range is refused before anything is sent. ``--json`` carries raw values.
"""

import argparse
import json
import os
import sys

from obsw_host.commands import arguments, session
from obsw_host.errors import UserError
from obsw_host.mission import ids as mission_ids
from obsw_host.net import DEFAULT_HOST


def add_parser(sub):
    p = sub.add_parser(
        "ground",
        help="send PUS requests to an on-board process, monitor its TM",
        description=__doc__,
        formatter_class=_raw(),
    )
    mission_ids.add_arguments(p)
    p.add_argument("--host", default=DEFAULT_HOST, help="on-board host (default %(default)s)")
    p.add_argument("--port", type=int, help="on-board UDP port (default: the mission's)")
    p.add_argument("--apid", type=int, help="on-board APID (default: the database's 'pus')")
    p.add_argument("--timeout", type=float, default=2.0, help="seconds per request")
    p.add_argument("--json", action="store_true", help="print JSON for scripts")
    p.add_argument("-v", "--verbose", action="store_true", help="print every packet")
    p.add_argument(
        "--log",
        metavar="FILE",
        default=os.environ.get("OBSW_SESSION_LOG") or None,
        help="append every TC and TM to this session log (default: $OBSW_SESSION_LOG)",
    )
    p.add_argument(
        "--raw", action="store_true", help="raw parameter values (default: engineering values)"
    )
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True
    from obsw_host.commands import cfdp, obcp

    obcp.add_to_ground(s)
    cfdp.add_parser(s)  # obsw ground cfdp put|get|status|serve
    from obsw_host.commands import ground_console, ground_data, ground_memory, ground_services

    ground_services.add_to_ground(s)  # obsw ground device|diag|functional|forward (2, 3, 14)
    ground_memory.add_to_ground(s)  # obsw ground memory ..|store ..
    ground_console.add_to_ground(s)  # obsw ground watch|console
    ground_data.add_to_ground(s)  # obsw ground stats|store ..|file (services 4, 15, 23)

    _add_operator(s)
    s.add_parser("ping", help="TC[17,1] are-you-alive").set_defaults(func=_ping)
    c = s.add_parser("connection", help="TC[17,3] on-board connection test")
    c.add_argument("target", type=int, help="APID of the process to test")
    c.set_defaults(func=_connection)

    hk = s.add_parser("hk", help="service 3 housekeeping").add_subparsers(dest="hk")
    hk.required = True
    r = hk.add_parser("report", help="TC[3,27] one-shot report")
    r.add_argument("sid", type=int)
    r.set_defaults(func=_hk_report)
    for name, helptext in (
        ("structures", "TC[3,9] structure reports"),
        ("properties", "TC[3,33] periodic generation properties"),
        ("enable", "TC[3,5] enable periodic reports"),
        ("disable", "TC[3,6] disable periodic reports"),
        ("delete", "TC[3,3] delete structures"),
    ):
        x = hk.add_parser(name, help=helptext)
        x.add_argument("sids", type=int, nargs="+")
        x.set_defaults(func=_hk_sids, hk_action=name)
    x = hk.add_parser("create", help="TC[3,1] create a structure")
    x.add_argument("sid", type=int)
    x.add_argument("interval", type=int, help="collection interval in on-board cycles")
    x.add_argument("parameters", nargs="+", help="parameter names or IDs")
    x.set_defaults(func=_hk_create)
    x = hk.add_parser("interval", help="TC[3,31] modify a collection interval")
    x.add_argument("sid", type=int)
    x.add_argument("interval", type=int)
    x.set_defaults(func=_hk_interval)
    x = hk.add_parser("listen", help="print periodic reports")
    x.add_argument("--seconds", type=arguments.seconds, default=3.0)
    x.set_defaults(func=session.listen, listen=(3, 25))
    ground_services.add_to_hk(hk)  # obsw ground hk append

    pa = s.add_parser("params", help="service 20 parameters").add_subparsers(dest="params")
    pa.required = True
    x = pa.add_parser("get", help="TC[20,1] report values")
    x.add_argument("names", nargs="+")
    x.set_defaults(func=_params_get)
    x = pa.add_parser("set", help="TC[20,3] set values")
    x.add_argument("assignments", nargs="+", metavar="NAME=VALUE")
    x.set_defaults(func=_params_set)
    _add_values_commands(s, pa)

    ev = s.add_parser("events", help="service 5 events").add_subparsers(dest="events")
    ev.required = True
    ev.add_parser("disabled", help="TC[5,7] disabled list").set_defaults(func=_events_disabled)
    for name in ("enable", "disable"):
        x = ev.add_parser(name, help="TC[5,%d] %s events" % (5 if name == "enable" else 6, name))
        x.add_argument("names", nargs="+")
        x.set_defaults(func=_events_switch, ev_action=name)
    x = ev.add_parser("listen", help="print event reports")
    x.add_argument("--seconds", type=arguments.seconds, default=3.0)
    x.set_defaults(func=session.listen, listen=(5, None))

    _add_automation(s)

    ti = s.add_parser("time", help="service 9 time").add_subparsers(dest="time")
    ti.required = True
    x = ti.add_parser("rate", help="TC[9,1] report every 2**EXPONENT s")
    x.add_argument("exponent", type=int)
    x.set_defaults(func=_time_rate)
    x = ti.add_parser("listen", help="print time reports (CUC TM[9,2] or CDS TM[9,3])")
    x.add_argument("--seconds", type=arguments.seconds, default=3.0)
    x.set_defaults(func=session.listen, listen=(9, None))


def _add_automation(s):
    x = s.add_parser("function", help="TC[8,1] perform a function")
    x.add_argument("name", help="function name or ID")
    x.add_argument("arguments", nargs="*", metavar="ARG=VALUE")
    x.set_defaults(func=_function)
    x = s.add_parser(
        "service",
        help="a request of a mission service (types 128..255; `list services` names them)",
    )
    x.add_argument("service", help="mission service name or type")
    x.add_argument("request", help="request name or subtype")
    x.add_argument("arguments", nargs="*", metavar="ARG=VALUE")
    x.set_defaults(func=_service)

    for svc, name, tag in (("schedule", "time-based", "--in"), ("position", "position-based", "")):
        sp = s.add_parser(
            svc, help="service %s %s scheduling" % ((11, 22)[svc == "position"], name)
        )
        sp = sp.add_subparsers(dest=svc)
        sp.required = True
        x = sp.add_parser("insert", help="insert one activity")
        if tag:
            when = x.add_mutually_exclusive_group(required=True)
            when.add_argument("--in", dest="delay", type=float, help="seconds from now")
            when.add_argument("--at", help="UTC release time, YYYY-MM-DDTHH:MM:SS[.fff]Z")
        else:
            x.add_argument("position", type=int)
        x.add_argument("--subschedule", type=int, default=0)
        x.add_argument("--group", type=int, default=0)
        x.add_argument("request", nargs="+", help="ping | function NAME ARG=V.. | set NAME=V..")
        x.set_defaults(func=_sched_insert, service=svc)
        for action in ("list", "summary", "enable", "disable", "reset"):
            sp.add_parser(action).set_defaults(func=_sched_simple, service=svc, what=action)
        x = sp.add_parser("shift", help="shift all activities (or --ids)")
        x.add_argument("offset", type=float)
        x.add_argument("--ids", nargs="+", metavar="SOURCE:APID:SEQ")
        x.set_defaults(func=_sched_shift, service=svc)
        x = sp.add_parser("delete", help="delete activities")
        x.add_argument("ids", nargs="+", metavar="SOURCE:APID:SEQ")
        x.set_defaults(func=_sched_delete, service=svc)
        if svc == "position":
            from obsw_host.commands import ground_memory

            ground_memory.add_to_position(sp)  # obsw ground position orbit N

    mo = s.add_parser(
        "monitor",
        help="live TM view (no ACTION); or service 12 on-board monitoring (ACTION)",
        description="Without ACTION: print every TM as it arrives until Ctrl-C (or --seconds, "
        "--count). With ACTION: service 12 on-board monitoring.",
    )
    mo.add_argument("--seconds", type=arguments.seconds, help="stop after this many seconds")
    mo.add_argument("--count", type=arguments.count, help="stop after this many TM packets")
    mo.add_argument("--colour", choices=("auto", "always", "never"), default="auto")
    mo.add_argument("--log", metavar="FILE", default=argparse.SUPPRESS, help="session log")
    mo.set_defaults(func=_monitor_live)
    mo = mo.add_subparsers(dest="mon", metavar="ACTION")
    x = mo.add_parser("add", help="TC[12,5] add a limit check and enable it")
    x.add_argument("pmon", type=int)
    x.add_argument("parameter")
    x.add_argument("low", type=float)
    x.add_argument("high", type=float)
    x.add_argument("--low-event", default="0")
    x.add_argument("--high-event", default="0")
    x.add_argument("--repetitions", type=int, default=1)
    x.add_argument("--interval", type=int, default=1, help="in on-board cycles")
    x.set_defaults(func=_monitor_add)
    for action in ("list", "out-of-limits"):
        mo.add_parser(action).set_defaults(func=_monitor_simple, what=action)
    for action in ("enable", "disable", "delete"):
        x = mo.add_parser(action)
        x.add_argument("ids", type=int, nargs="+")
        x.set_defaults(func=_monitor_ids, what=action)

    ac = s.add_parser("action", help="service 19 event-action").add_subparsers(dest="act")
    ac.required = True
    x = ac.add_parser("add", help="TC[19,1] run a request on an event, and enable it")
    x.add_argument("event")
    x.add_argument("request", nargs="+")
    x.set_defaults(func=_action_add)
    ac.add_parser("list").set_defaults(func=_action_list)
    for action in ("enable", "disable", "delete"):
        x = ac.add_parser(action)
        x.add_argument("events", nargs="+")
        x.set_defaults(func=_action_events, what=action)

    se = s.add_parser("sequence", help="service 21 request sequencing").add_subparsers(dest="seq")
    se.required = True
    x = se.add_parser("load", help='TC[21,1]: steps like "DELAY REQUEST.."')
    x.add_argument("name")
    x.add_argument("steps", nargs="+")
    x.set_defaults(func=_sequence_load)
    se.add_parser("status").set_defaults(func=_sequence_status)
    from obsw_host.commands import ground_memory

    ground_memory.add_to_sequence(se)  # obsw ground sequence file|load-file
    for action in ("content", "activate", "abort", "unload"):
        x = se.add_parser(action)
        x.add_argument("name")
        x.set_defaults(func=_sequence_named, what=action)


def _add_operator(s):
    x = s.add_parser("replay", help="print a session log (--log) decoded again")
    x.add_argument("session_log", metavar="LOG", help="a file written by --log")
    x.add_argument("--colour", choices=("auto", "always", "never"), default="auto")
    x.set_defaults(func=_replay)
    x = s.add_parser("list", help="parameters, functions, events, hk, obcps, files")
    x.add_argument(
        "kind",
        choices=("parameters", "functions", "events", "hk", "services", "obcps", "files"),
        help="what to list (obcps and files ask the on-board process)",
    )
    x.add_argument(
        "repository", nargs="?", help="for files (default: the mission's onboard filestore)"
    )
    x.set_defaults(func=_list)


def _raw():
    return argparse.RawDescriptionHelpFormatter


def _colour(args):
    return args.colour == "always" or (args.colour == "auto" and sys.stdout.isatty())


def _monitor_live(args):
    """Every TM as it comes, until Ctrl-C, --seconds or --count."""
    import time

    from obsw_host.pus import text
    from obsw_host.pus.monitor import Display
    from obsw_host.pus.tm_fanout import LINGER

    seen = [0]
    with session.ground(args) as g:
        display = Display(g.sdb, _colour(args), getattr(args, "raw", False), g.proc.config)

        def show(tm, decoded, tx):
            seen[0] += 1
            if args.json:
                record = {"type": [tm.service, tm.subtype], "apid": tm.apid}
                record["seq_count"] = tm.seq_count
                record["value"] = text.plain(decoded)
                print(json.dumps(record), flush=True)
            else:
                print(display.tm(tm, decoded), flush=True)

        g.proc.listeners.append(show)
        g.subscribe()
        print(
            "monitoring TM from %s:%d (Ctrl-C stops)" % g.target[:2], file=sys.stderr, flush=True
        )
        now = time.monotonic
        end = None if args.seconds is None else now() + args.seconds
        refresh = now() + LINGER / 3
        while end is None or now() < end:
            if args.count is not None and seen[0] >= args.count:
                break
            g.poll(0.2 if end is None else max(0.0, min(0.2, end - now())))
            if now() >= refresh:
                g.subscribe()
                refresh = now() + LINGER / 3
    return 0


def _replay(args):
    from obsw_host.pus.monitor import replay

    for line in replay(args.session_log, mission_ids.from_args(args).sdb, _colour(args)):
        print(line)
    return 0


def _list(args):
    from obsw_host.pus.catalog import KINDS, catalog, table

    if args.kind in KINDS:
        rows = catalog(mission_ids.from_args(args).sdb, args.kind)
        print(json.dumps(rows) if args.json else table(rows))
        return 0
    if args.kind == "obcps":
        from obsw_host.pus.obcp_ground import ObcpGround

        return session.run(args, lambda g: ObcpGround(g).report_status())
    from obsw_host.pus.storage_ground import StorageGround

    repository = args.repository or "%s:/" % mission_ids.from_args(args).local_prefix
    return session.run(args, lambda g: StorageGround(g).directory(repository))


def _ping(args):
    return session.run(args, lambda g: g.ping())


def _connection(args):
    return session.run(args, lambda g: g.connection_test(args.target))


def _hk_report(args):
    return session.run(args, lambda g: g.housekeeping(args.sid))


def _hk_sids(args):
    method = {
        "structures": "hk_structures",
        "properties": "hk_properties",
        "enable": "enable_hk",
        "disable": "disable_hk",
        "delete": "delete_hk",
    }[args.hk_action]
    return session.run(args, lambda g: getattr(g, method)(args.sids))


def _hk_create(args):
    params = [session.key(p) for p in args.parameters]
    return session.run(args, lambda g: g.create_hk(args.sid, args.interval, params))


def _hk_interval(args):
    return session.run(args, lambda g: g.set_hk_interval(args.sid, args.interval))


def _params_get(args):
    return session.run(args, lambda g: g.get_parameters(*[session.key(n) for n in args.names]))


def _params_set(args):
    values = {}
    for a in args.assignments:
        name, sep, value = a.partition("=")
        if not sep:
            raise UserError("parameter assignment %r" % a, expected="NAME=VALUE")
        values[session.key(name)] = session.value(value)
    return session.run(args, lambda g: g.set_parameters(values, raw=args.raw))


def _events_disabled(args):
    return session.run(args, lambda g: g.disabled_events())


def _events_switch(args):
    keys = [session.key(n) for n in args.names]
    if args.ev_action == "enable":
        return session.run(args, lambda g: g.enable_events(keys))
    return session.run(args, lambda g: g.disable_events(keys))


def _time_rate(args):
    return session.run(args, lambda g: g.set_time_rate(args.exponent))


# ------------------------------------------------------------------------------ automation


def _rid(text):
    try:
        source, apid, seq = (int(x) for x in text.split(":"))
    except ValueError:
        raise UserError("activity %r" % text, expected="SOURCE:APID:SEQ") from None
    return (source, apid, seq)


def _function(args):
    def go(g):
        values = {str(k): v for k, v in session.assignments(args.arguments).items()}
        return g.perform(session.key(args.name), **values)

    return session.run(args, go)


def _service(args):
    return session.run(
        args,
        lambda g: session.mission_call(g.call_service, args.service, args.request, args.arguments),
    )


def _sched_insert(args):
    def go(g):
        request = session.request(session.fresh(g), args.request)
        if args.service == "position":
            user = g.position
            item = (args.position, request, args.subschedule, args.group)
        else:
            from obsw.utc import parse_utc

            from obsw_host.pus.tai import tai_now

            at = parse_utc(args.at) if args.at else tai_now() + args.delay
            user = g.schedule
            item = (at, request, args.subschedule, args.group)
        return g.issue(user.insert(g.apid, [item]))

    return session.run(args, go)


def _sched_user(g, args):
    return g.position if args.service == "position" else g.schedule


def _sched_simple(args):
    def go(g):
        user = _sched_user(g, args)
        fn = {
            "list": user.detail_all,
            "summary": user.summary_all,
            "enable": user.enable,
            "disable": user.disable,
            "reset": user.reset,
        }[args.what]
        return g.issue(fn(g.apid))

    return session.run(args, go)


def _sched_shift(args):
    def go(g):
        user = _sched_user(g, args)
        offset = int(args.offset) if args.service == "position" else args.offset
        if args.ids:
            return g.issue(user.shift(g.apid, offset, [_rid(i) for i in args.ids]))
        return g.issue(user.shift_all(g.apid, offset))

    return session.run(args, go)


def _sched_delete(args):
    return session.run(
        args, lambda g: g.issue(_sched_user(g, args).delete(g.apid, [_rid(i) for i in args.ids]))
    )


def _monitor_add(args):
    def go(g):
        return g.add_limit_monitor(
            args.pmon,
            session.key(args.parameter),
            args.low,
            args.high,
            session.key(args.low_event),
            session.key(args.high_event),
            repetitions=args.repetitions,
            interval=args.interval,
            raw=args.raw,
        )

    return session.run(args, go)


def _monitor_simple(args):
    if args.what == "list":
        return session.run(args, lambda g: g.monitors())
    return session.run(args, lambda g: g.out_of_limits())


def _monitor_ids(args):
    if args.what == "delete":
        return session.run(args, lambda g: g.delete_monitors(args.ids))
    return session.run(args, lambda g: g.enable_monitors(args.ids, args.what == "enable"))


def _action_add(args):
    return session.run(
        args,
        lambda g: g.add_action(
            session.key(args.event), session.request(session.fresh(g), args.request)
        ),
    )


def _action_list(args):
    return session.run(args, lambda g: g.actions())


def _action_events(args):
    events = [session.key(e) for e in args.events]
    if args.what == "delete":
        return session.run(args, lambda g: g.delete_actions(events))
    return session.run(args, lambda g: g.enable_actions(events, args.what == "enable"))


def _sequence_load(args):
    import shlex

    def go(g):
        session.fresh(g)
        items = []
        for step in args.steps:
            words = shlex.split(step)
            try:
                delay = float(words[0])
            except (ValueError, IndexError):
                raise UserError("sequence step %r" % step, expected="'DELAY REQUEST..'") from None
            items.append((session.request(g, words[1:]), delay))
        return g.load_sequence(args.name, items)

    return session.run(args, go)


def _sequence_status(args):
    return session.run(args, lambda g: g.sequences())


def _sequence_named(args):
    method = {
        "content": "sequence_content",
        "activate": "activate_sequence",
        "abort": "abort_sequence",
        "unload": "unload_sequence",
    }[args.what]
    return session.run(args, lambda g: getattr(g, method)(args.name))


# ------------------------------------- parameter definitions (20), functional monitoring (12)


def _add_values_commands(s, params):
    x = params.add_parser("definitions", help="TC[20,6] where parameters live (all if none)")
    x.add_argument("names", nargs="*")
    x.set_defaults(func=_params_definitions)
    x = params.add_parser("define", help="TC[20,4] place a parameter in a memory area")
    x.add_argument("name")
    x.add_argument("memory", type=int, help="memory ID (the database's memories)")
    x.add_argument("address", type=int, help="absolute address (--object: offset in it)")
    x.add_argument(
        "--object", type=int, metavar="ID", help="TC[20,5]: in object ID (0: the whole area)"
    )
    x.set_defaults(func=_params_define)
    fm = s.add_parser("fmon", help="service 12 functional monitoring").add_subparsers(dest="fm")
    fm.required = True
    x = fm.add_parser("add", help="TC[12,23] an FMON over PMONs (disabled)")
    x.add_argument("fmon", type=int)
    x.add_argument("pmons", type=int, nargs="+")
    x.add_argument("--failing", type=int, default=1, help="minimum failing PMONs")
    x.add_argument("--event", default="0", help="event raised when it fails")
    x.set_defaults(func=_fmon_add)
    fm.add_parser("list", help="TC[12,25]").set_defaults(func=_fmon_report, what="list")
    fm.add_parser("status", help="TC[12,27]").set_defaults(func=_fmon_report, what="status")
    for action in ("enable-function", "disable-function"):
        fm.add_parser(action).set_defaults(func=_fmon_action, what=action)
    for action in ("enable", "disable", "protect", "unprotect", "delete"):
        x = fm.add_parser(action)
        x.add_argument("ids", type=int, nargs="+")
        x.set_defaults(func=_fmon_action, what=action)


def _params_definitions(args):
    return session.run(
        args, lambda g: g.parameter_definitions([session.key(n) for n in args.names])
    )


def _params_define(args):
    if args.object is None:
        item = (session.key(args.name), args.memory, args.address)
    else:
        item = (session.key(args.name), args.memory, args.object, args.address)
    return session.run(args, lambda g: g.define_parameters([item], args.object is not None))


def _fmon_add(args):
    return session.run(
        args,
        lambda g: g.add_functional_monitor(
            args.fmon, args.pmons, args.failing, session.key(args.event)
        ),
    )


def _fmon_report(args):
    if args.what == "list":
        return session.run(args, lambda g: g.functional_monitors())
    return session.run(args, lambda g: g.functional_status())


def _fmon_action(args):
    return session.run(args, lambda g: g.functional_request(args.what, getattr(args, "ids", ())))
