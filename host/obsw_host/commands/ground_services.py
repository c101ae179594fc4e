"""`obsw ground` subcommands for the device-level, diagnostic, functional reporting and
diagnostic forwarding requests (services 2, 3 and 14).

    obsw ground device on-off 0x0A81 0x0A00     TC[2,1] on/off device commands
    obsw ground device load 0x000A0001=0x0004   TC[2,2] register load commands
    obsw ground device dump 0x000A0001          TC[2,5] -> TM[2,6] register dump
    obsw ground device cpdu 0x0A01:500          TC[2,4] CPDU commands (line:ms)
    obsw ground hk append 1 SolarPanel.speed    TC[3,29] (--diag: TC[3,30])
    obsw ground diag create 5 1 SolarPanel.angle    TC[3,2]; report, structures, properties,
                                                enable, disable, delete, interval, listen
    obsw ground functional create 1 --hk 1:on:2 --diag 5:off:1    TC[3,38]; apply, delete,
                                                report, add, remove, modify
    obsw ground forward diag add 10:5           TC[14,9]; delete (TC[14,10]), report
    obsw ground tc 3 40 0000                    any TC: service, subtype, application data
                                                in hex; the replies decoded by the users

On SpaceCAN, an on/off address is node << 8 | on << 7 | line, a register address
node << 16 | parameter id, a CPDU line node << 8 | output line (obsw.spacecan.device_access).
"""

from obsw_host.commands import ground_data, session
from obsw_host.errors import UserError
from obsw_host.pus import text

_ON = {"on": True, "1": True, "enabled": True, "off": False, "0": False, "disabled": False}


def _int(text):
    try:
        return int(text, 0)
    except ValueError:
        raise UserError("number %r" % text, expected="a decimal or 0x hex integer") from None


def _pair(text, sep, what):
    a, s, b = text.partition(sep)
    if not s:
        raise UserError("%s %r" % (what, text), expected="A%sB" % sep)
    return _int(a), _int(b)


def _key(text):
    return int(text) if text.isdigit() else text


def _param_ids(g, names):
    out = []
    for n in names:
        k = _key(n)
        out.append(k if isinstance(k, int) or g.sdb is None else g.sdb.parameter(k).id)
    return out


def _definitions(items):
    """SID:on|off:INTERVAL items -> {sid: (enabled, interval)}."""
    out = {}
    for item in items or ():
        parts = item.split(":")
        if len(parts) != 3 or parts[1].lower() not in _ON:
            raise UserError("report definition %r" % item, expected="SID:on|off:INTERVAL")
        out[_int(parts[0])] = (_ON[parts[1].lower()], _int(parts[2]))
    return out


def _issue(g, tx):
    if g.log is not None:
        g.log(text.tc_line(tx.tc))
    return g.wait(tx)


def _storage(g):
    from obsw_host.pus.storage_ground import StorageGround

    return StorageGround(g)


# ------------------------------------------------------------------------------ parsers


def add_to_hk(hk):
    """`obsw ground hk append`."""
    x = hk.add_parser("append", help="TC[3,29] append parameters to a structure (disabled)")
    x.add_argument("sid", type=int)
    x.add_argument("parameters", nargs="+", help="parameter names or IDs")
    x.add_argument("--diag", action="store_true", help="a diagnostic structure: TC[3,30]")
    x.set_defaults(func=_append)


def add_to_ground(s):
    """`obsw ground device|diag|functional|forward`."""
    dv = s.add_parser("device", help="service 2 device-level commands").add_subparsers(dest="dev")
    dv.required = True
    x = dv.add_parser("on-off", help="TC[2,1] on/off device commands")
    x.add_argument("addresses", nargs="+", help="on/off device addresses")
    x.set_defaults(func=_device, what="on-off")
    x = dv.add_parser("load", help="TC[2,2] register load commands")
    x.add_argument("assignments", nargs="+", metavar="ADDRESS=VALUE")
    x.set_defaults(func=_device, what="load")
    x = dv.add_parser("dump", help="TC[2,5] dump registers (TM[2,6])")
    x.add_argument("addresses", nargs="+", help="register addresses")
    x.set_defaults(func=_device, what="dump")
    x = dv.add_parser("cpdu", help="TC[2,4] CPDU commands")
    x.add_argument("pulses", nargs="+", metavar="LINE:MS", help="output line and duration")
    x.set_defaults(func=_device, what="cpdu")

    dg = s.add_parser("diag", help="service 3 diagnostic reports").add_subparsers(dest="diag")
    dg.required = True
    x = dg.add_parser("report", help="TC[3,28] one-shot diagnostic report")
    x.add_argument("sid", type=int)
    x.set_defaults(func=_diag, what="report")
    for name, helptext in (
        ("structures", "TC[3,11] structure reports"),
        ("properties", "TC[3,34] periodic generation properties"),
        ("enable", "TC[3,7] enable periodic reports"),
        ("disable", "TC[3,8] disable periodic reports"),
        ("delete", "TC[3,4] delete structures"),
    ):
        x = dg.add_parser(name, help=helptext)
        x.add_argument("sids", type=int, nargs="+")
        x.set_defaults(func=_diag, what=name)
    x = dg.add_parser("create", help="TC[3,2] create a diagnostic structure")
    x.add_argument("sid", type=int)
    x.add_argument("interval", type=int, help="collection interval in on-board cycles")
    x.add_argument("parameters", nargs="+", help="parameter names or IDs")
    x.set_defaults(func=_diag, what="create")
    x = dg.add_parser("interval", help="TC[3,32] modify a collection interval")
    x.add_argument("sid", type=int)
    x.add_argument("interval", type=int)
    x.set_defaults(func=_diag, what="interval")
    x = dg.add_parser("listen", help="print periodic diagnostic reports")
    x.add_argument("--seconds", type=float, default=3.0)
    x.set_defaults(func=session.listen, listen=(3, 26))

    fr = s.add_parser("functional", help="service 3 parameter functional reporting")
    fr = fr.add_subparsers(dest="functional")
    fr.required = True
    for name, helptext in (
        ("create", "TC[3,38] create a definition"),
        ("add", "TC[3,42] add report definitions to a definition"),
        ("modify", "TC[3,44] modify report definitions of a definition"),
    ):
        x = fr.add_parser(name, help=helptext)
        x.add_argument("id", type=int)
        x.add_argument("--hk", action="append", metavar="SID:on|off:INTERVAL")
        x.add_argument("--diag", action="append", metavar="SID:on|off:INTERVAL")
        x.set_defaults(func=_functional, what=name)
    x = fr.add_parser("remove", help="TC[3,43] remove report definitions from a definition")
    x.add_argument("id", type=int)
    x.add_argument("--hk", type=int, action="append", default=[], metavar="SID")
    x.add_argument("--diag", type=int, action="append", default=[], metavar="SID")
    x.set_defaults(func=_functional, what="remove")
    for name, helptext in (
        ("apply", "TC[3,37] apply definitions"),
        ("delete", "TC[3,39] delete definitions (none named: all)"),
        ("report", "TC[3,40] report definitions (none named: all)"),
    ):
        x = fr.add_parser(name, help=helptext)
        x.add_argument("ids", type=int, nargs="*" if name != "apply" else "+")
        x.set_defaults(func=_functional, what=name)

    fw = s.add_parser("forward", help="service 14 real-time forwarding of diagnostic reports")
    fw = fw.add_subparsers(dest="forward")
    fw.required = True
    dd = fw.add_parser("diag", help="diagnostic structure IDs forwarded").add_subparsers(dest="fd")
    dd.required = True
    for name, helptext in (
        ("add", "TC[14,9] forward these APID:SID (APID alone: every SID)"),
        ("delete", "TC[14,10] stop forwarding these (none: all)"),
    ):
        x = dd.add_parser(name, help=helptext)
        x.add_argument("items", nargs="*" if name == "delete" else "+", metavar="APID[:SID]")
        x.set_defaults(func=_forward, what=name)
    dd.add_parser("report", help="TC[14,11] the configuration (TM[14,12])").set_defaults(
        func=_forward, what="report"
    )

    x = s.add_parser(
        "tc",
        help="any TC: by name from the database, or by service, subtype and data in hex",
        description="`tc FUNCTION [ARG=VALUE..]` (TC[8,1]) or `tc PARAMETER=VALUE..` "
        "(TC[20,3]) by name from the database, every value checked against its type and the "
        "database's range before anything is sent; or `tc SERVICE SUBTYPE [HEX]`.",
    )
    x.add_argument("what", metavar="NAME|SERVICE", help="a function, PARAMETER=VALUE, or a number")
    x.add_argument("rest", nargs="*", metavar="ARG=VALUE|SUBTYPE [HEX]")
    x.set_defaults(func=_tc)


# ------------------------------------------------------------------------------ actions


def _run(args, fn):
    return session.run(args, fn)


def _device(args):
    def go(g):
        dev = _storage(g).devices
        if args.what == "on-off":
            return _issue(g, dev.on_off(g.apid, [_int(a) for a in args.addresses]))
        if args.what == "dump":
            return _issue(g, dev.dump_registers(g.apid, [_int(a) for a in args.addresses]))
        if args.what == "load":
            values = dict(_pair(a, "=", "register assignment") for a in args.assignments)
            return _issue(g, dev.load_registers(g.apid, values))
        return _issue(g, dev.cpdu(g.apid, [_pair(p, ":", "CPDU pulse") for p in args.pulses]))

    return _run(args, go)


def _append(args):
    def go(g):
        kind = "diag" if args.diag else "hk"
        return _issue(g, g.hk.append(g.apid, args.sid, _param_ids(g, args.parameters), kind))

    return _run(args, go)


def _diag(args):
    def go(g):
        hk, apid, w = g.hk, g.apid, args.what
        if w == "report":
            return g.housekeeping(args.sid, kind="diag")
        if w == "create":
            params = _param_ids(g, args.parameters)
            return _issue(g, hk.create(apid, args.sid, args.interval, params, "diag"))
        if w == "interval":
            return _issue(g, hk.modify_interval(apid, {args.sid: args.interval}, "diag"))
        method = {"structures": "report_structures", "properties": "report_properties"}
        return _issue(g, getattr(hk, method.get(w, w))(apid, args.sids, "diag"))

    return _run(args, go)


def _functional(args):
    def go(g):
        hk, apid, w = g.hk, g.apid, args.what
        if w in ("apply", "delete", "report"):
            return _issue(g, getattr(hk, w + "_functional")(apid, args.ids))
        if w == "remove":
            return _issue(g, hk.remove_from_functional(apid, args.id, args.hk, args.diag))
        method = {"create": "create_functional", "add": "add_to_functional"}
        fn = getattr(hk, method.get(w, "modify_functional"))
        return _issue(g, fn(apid, args.id, _definitions(args.hk), _definitions(args.diag)))

    return _run(args, go)


def _forward(args):
    def go(g):
        fwd = _storage(g).forwarding
        if args.what == "report":
            return _issue(g, fwd.report_diag(g.apid))
        selection = {}
        for item in args.items:
            apid, _, sid = item.partition(":")
            ids = selection.setdefault(_int(apid), [])
            if sid:
                ids.append(_int(sid))
        if args.what == "add":
            return _issue(g, fwd.add_diag(g.apid, selection))
        return _issue(g, fwd.delete_diag(g.apid, selection))

    return _run(args, go)


def _tc(args):
    if not args.what.isdigit():
        return ground_data.tc_by_name(args)  # a function or parameters, typed and checked
    if not 1 <= len(args.rest) <= 2:
        raise UserError(
            "tc %s" % " ".join([args.what] + args.rest), expected="SERVICE SUBTYPE [HEX]"
        )
    args.service, args.subtype = int(args.what), _int(args.rest[0])
    args.data = args.rest[1] if len(args.rest) > 1 else ""
    try:
        data = bytes.fromhex(args.data)
    except ValueError:
        raise UserError("application data %r" % args.data, expected="hex octets") from None
    for what, value in (("service", args.service), ("subtype", args.subtype)):
        if not 0 <= value <= 255:
            raise UserError("%s %d" % (what, value), expected="0 to 255")

    def go(g):
        _storage(g)  # the users of services 2, 4, 6, 13, 14, 15, 23 decode their reports too
        mark = len(g.received)
        tx = g.wait(g.send(g.apid, args.service, args.subtype, data))
        # no reply type is expected of a TC sent by numbers: the reports of its service sent
        # to this ground while it ran are its replies
        for tm, decoded in g.received[mark:]:
            if tm.service == args.service and tm.destination_id == g.proc.source_id:
                tx.replies.append(decoded)
        return tx

    return _run(args, go)
