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
    obsw ground events disabled | enable NAME.. | disable NAME.. | listen
    obsw ground time rate 0 | listen
    obsw ground connection 10

``--json`` prints one JSON object per command instead of text; ``-v`` shows every packet.
"""

import json
import sys


def add_parser(sub):
    p = sub.add_parser(
        "ground",
        help="send PUS requests to an on-board process",
        description=__doc__,
        formatter_class=_raw(),
    )
    p.add_argument("--sdb", help="spacecraft database JSON (default: the sample database)")
    p.add_argument("--host", default="127.0.0.1", help="on-board host (default %(default)s)")
    p.add_argument("--port", type=int, help="on-board UDP port (default 5000 + APID)")
    p.add_argument("--apid", type=int, help="on-board APID (default: the database's 'pus')")
    p.add_argument("--timeout", type=float, default=2.0, help="seconds per request")
    p.add_argument("--json", action="store_true", help="print JSON for scripts")
    p.add_argument("-v", "--verbose", action="store_true", help="print every packet")
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True

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
    x.add_argument("--seconds", type=float, default=3.0)
    x.set_defaults(func=_listen, listen=(3, 25))

    pa = s.add_parser("params", help="service 20 parameters").add_subparsers(dest="params")
    pa.required = True
    x = pa.add_parser("get", help="TC[20,1] report values")
    x.add_argument("names", nargs="+")
    x.set_defaults(func=_params_get)
    x = pa.add_parser("set", help="TC[20,3] set values")
    x.add_argument("assignments", nargs="+", metavar="NAME=VALUE")
    x.set_defaults(func=_params_set)

    ev = s.add_parser("events", help="service 5 events").add_subparsers(dest="events")
    ev.required = True
    ev.add_parser("disabled", help="TC[5,7] disabled list").set_defaults(func=_events_disabled)
    for name in ("enable", "disable"):
        x = ev.add_parser(name, help="TC[5,%d] %s events" % (5 if name == "enable" else 6, name))
        x.add_argument("names", nargs="+")
        x.set_defaults(func=_events_switch, ev_action=name)
    x = ev.add_parser("listen", help="print event reports")
    x.add_argument("--seconds", type=float, default=3.0)
    x.set_defaults(func=_listen, listen=(5, None))

    ti = s.add_parser("time", help="service 9 time").add_subparsers(dest="time")
    ti.required = True
    x = ti.add_parser("rate", help="TC[9,1] report every 2**EXPONENT s")
    x.add_argument("exponent", type=int)
    x.set_defaults(func=_time_rate)
    x = ti.add_parser("listen", help="print time reports")
    x.add_argument("--seconds", type=float, default=3.0)
    x.set_defaults(func=_listen, listen=(9, 2))


def _raw():
    import argparse

    return argparse.RawDescriptionHelpFormatter


def _ground(args):
    from obsw import sdb as sdb_module

    from obsw_host.pus.demo import SDB_PATH
    from obsw_host.pus.ground import Ground

    sdb = sdb_module.load(args.sdb or SDB_PATH)
    apid = args.apid if args.apid is not None else sdb.apid("pus")
    target = (args.host, args.port if args.port is not None else 5000 + apid)
    log = (lambda s: print(s, file=sys.stderr)) if args.verbose else None
    return Ground(sdb, apid=apid, target=target, timeout=args.timeout, log=log)


def _run(args, fn):
    from obsw_host.pus import text
    from obsw_host.pus.ground import PusTimeout

    with _ground(args) as g:
        try:
            tx = fn(g)
        except PusTimeout as e:
            tx = e.transaction
        except KeyError as e:
            print("obsw ground: %s" % e.args[0], file=sys.stderr)
            return 2
    result = text.transaction(tx)
    if args.json:
        print(json.dumps(result))
    else:
        for line in tx.verification():
            print("  " + line)
        for reply in tx.replies:
            print(_format(reply))
        if not tx.done:
            print("no completion report within %ss" % args.timeout)
    return 0 if tx.ok else 1


def _format(value):
    from obsw_host.pus import text

    v = text.plain(value)
    if isinstance(v, dict) and "values" in v and isinstance(v["values"], dict):
        lines = ["%s = %s" % (k, x) for k, x in v["values"].items()]
        head = "structure %s" % v["sid"] if "sid" in v else None
        return "\n".join(([head] if head else []) + lines)
    return json.dumps(v)


def _ping(args):
    return _run(args, lambda g: g.ping())


def _connection(args):
    return _run(args, lambda g: g.connection_test(args.target))


def _hk_report(args):
    return _run(args, lambda g: g.housekeeping(args.sid))


def _hk_sids(args):
    method = {
        "structures": "hk_structures",
        "properties": "hk_properties",
        "enable": "enable_hk",
        "disable": "disable_hk",
        "delete": "delete_hk",
    }[args.hk_action]
    return _run(args, lambda g: getattr(g, method)(args.sids))


def _key(text):
    return int(text) if text.isdigit() else text


def _hk_create(args):
    params = [_key(p) for p in args.parameters]
    return _run(args, lambda g: g.create_hk(args.sid, args.interval, params))


def _hk_interval(args):
    return _run(args, lambda g: g.set_hk_interval(args.sid, args.interval))


def _params_get(args):
    return _run(args, lambda g: g.get_parameters(*[_key(n) for n in args.names]))


def _value(text):
    try:
        return json.loads(text)
    except ValueError:
        return text


def _params_set(args):
    values = {}
    for a in args.assignments:
        name, sep, value = a.partition("=")
        if not sep:
            print("obsw ground params set: expected NAME=VALUE, got %r" % a, file=sys.stderr)
            return 2
        values[_key(name)] = _value(value)
    return _run(args, lambda g: g.set_parameters(values))


def _events_disabled(args):
    return _run(args, lambda g: g.disabled_events())


def _events_switch(args):
    keys = [_key(n) for n in args.names]
    if args.ev_action == "enable":
        return _run(args, lambda g: g.enable_events(keys))
    return _run(args, lambda g: g.disable_events(keys))


def _time_rate(args):
    return _run(args, lambda g: g.set_time_rate(args.exponent))


def _listen(args):
    """Print unsolicited TM of one type for a while (after a ping, so TM finds the way)."""
    from obsw_host.pus import text

    service, subtype = args.listen
    n = 0
    with _ground(args) as g:
        try:
            g.ping()
        except Exception as e:
            print("obsw ground: on-board process does not answer: %s" % e, file=sys.stderr)
            return 1
        import time

        end = time.monotonic() + args.seconds
        seen = len(g.received)
        while time.monotonic() < end:
            g.poll(min(0.1, max(0.0, end - time.monotonic())))
            for tm, decoded in g.received[seen:]:
                if service == 3 and decoded and "raw" in decoded:
                    decoded = _learn(g, tm, decoded)
                if tm.service == service and (subtype is None or tm.subtype == subtype):
                    n += 1
                    if args.json:
                        print(
                            json.dumps(
                                {"type": [tm.service, tm.subtype], "value": text.plain(decoded)}
                            )
                        )
                    else:
                        print(text.tm_line(tm, decoded))
            seen = len(g.received)
    return 0 if n else 1


def _learn(g, tm, decoded):
    """A report of a structure this ground has not seen: ask for its layout, decode again."""
    try:
        g.hk_structures([decoded["sid"]])
        return g.hk.decode_report(tm)
    except Exception:
        return decoded
