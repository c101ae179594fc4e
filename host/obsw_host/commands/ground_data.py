"""`obsw ground` subcommands for on-board statistics (service 4), packet stores and their
downlink (service 15) and files (service 23).

    obsw ground stats report [--reset]          TC[4,1] parameter statistics (TM[4,2])
    obsw ground stats reset | add SolarPanel.speed:10 | enable 50 | disable
    obsw ground store create 1 65536 [--bounded] [--vc 1]       TC[15,20] a packet store
    obsw ground store add-types 1 10:3:25 10:5  TC[15,3] what it stores (APID[:SVC[:SUB]])
    obsw ground store enable|disable [1 ..]     TC[15,1|2]
    obsw ground store summary [1 ..] | status   TC[15,12] / TC[15,18]
    obsw ground store downlink 1 --from 2030-01-01T00:00:00Z --to 2030-01-01T01:00:00Z
    obsw ground store downlink 1 --first 10 --last 200         TC[15,9] / TC[15,28]: on the
                                                store's virtual channel (the playback VC)
    obsw ground store delete-before 2030-01-01T00:00:00Z [1 ..] TC[15,11]
    obsw ground file copy SAT:/a.dat SAT:/b.dat [--move]        TC[23,14|15]
    obsw ground file attributes SAT:/a.dat | find SAT:/ "*.dat" | delete SAT:/b.dat
    obsw ground file create SAT:/log.txt [--max-size N] | mkdir SAT:/d | rmdir SAT:/d
    obsw ground large 17 1                      a TC (here TC[17,1]) in parts, TC[13,9..11];
    obsw ground large 6 2 --file patch.bin      its own verification reports at the end

Times are UTC (YYYY-MM-DDTHH:MM:SS[.fff]Z); replies print by name, as tables.
"""

import argparse

from obsw.pus.sdb import field_type
from obsw.utc import parse_utc

from obsw_host.commands import session
from obsw_host.errors import UserError


def add_to_ground(s):
    """Add ``stats`` and ``file``, and the service 15 store commands to ``store``."""
    st = s.add_parser("stats", help="service 4 parameter statistics").add_subparsers(dest="st4")
    st.required = True
    x = st.add_parser("report", help="TC[4,1] report the statistics (TM[4,2])")
    x.add_argument("--reset", action="store_true", help="and reset them")
    x.set_defaults(func=_stats, what="report")
    st.add_parser("reset", help="TC[4,3]").set_defaults(func=_stats, what="reset")
    x = st.add_parser("add", help="TC[4,6] parameters to sample, every N cycles")
    x.add_argument("items", nargs="+", metavar="PARAMETER:INTERVAL")
    x.set_defaults(func=_stats, what="add")
    x = st.add_parser("enable", help="TC[4,4] periodic reports every N cycles")
    x.add_argument("interval", type=int)
    x.set_defaults(func=_stats, what="enable")
    st.add_parser("disable", help="TC[4,5]").set_defaults(func=_stats, what="disable")

    _add_store(_subparsers(s.choices["store"]))

    x = s.add_parser(
        "large",
        help="service 13: send a TC in parts (TC[13,9..11]), e.g. one larger than the link takes",
    )
    x.add_argument("service", type=int)
    x.add_argument("subtype", type=int)
    x.add_argument("data", nargs="?", default="", help="application data, hex")
    x.add_argument("--file", help="application data from this file instead")
    x.add_argument("--part-size", type=int, default=256, help="octets per part (default 256)")
    x.set_defaults(func=_large)

    fi = s.add_parser("file", help="service 23 file management").add_subparsers(dest="f23")
    fi.required = True
    x = fi.add_parser("copy", help="TC[23,14] copy a file (--move: TC[23,15])")
    x.add_argument("source")
    x.add_argument("target")
    x.add_argument("--move", action="store_true")
    x.set_defaults(func=_file, what="copy")
    for name, helptext in (
        ("attributes", "TC[23,3] a file's attributes"),
        ("delete", "TC[23,2] delete a file"),
        ("mkdir", "TC[23,9] create a directory"),
        ("rmdir", "TC[23,10] delete a directory"),
    ):
        x = fi.add_parser(name, help=helptext)
        x.add_argument("path")
        x.set_defaults(func=_file, what=name)
    x = fi.add_parser("create", help="TC[23,1] create a file")
    x.add_argument("path")
    x.add_argument("--max-size", type=int, default=0)
    x.set_defaults(func=_file, what="create")
    x = fi.add_parser("find", help="TC[23,7] find files matching a pattern")
    x.add_argument("repository")
    x.add_argument("pattern")
    x.set_defaults(func=_file, what="find")


def _subparsers(parser):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return action
    raise LookupError("%s has no subcommands" % parser.prog)


def _add_store(st):
    x = st.add_parser("create", help="TC[15,20] create a packet store")
    x.add_argument("store", type=int)
    x.add_argument("size", type=int, help="bytes")
    x.add_argument("--bounded", action="store_true", help="bounded (default circular)")
    x.add_argument("--vc", type=int, help="virtual channel of its downlink (default playback)")
    x.set_defaults(func=_store, what="create")
    x = st.add_parser("add-types", help="TC[15,3] report types to store")
    x.add_argument("store", type=int)
    x.add_argument("types", nargs="+", metavar="APID[:SERVICE[:SUBTYPE]]")
    x.set_defaults(func=_store, what="add-types")
    for name in ("enable", "disable", "summary"):
        x = st.add_parser(name, help="TC[15,%d] (no STORE: every store)" % _SUBTYPE[name])
        x.add_argument("stores", type=int, nargs="*", metavar="STORE")
        x.set_defaults(func=_store, what=name)
    st.add_parser("status", help="TC[15,18] every store's status").set_defaults(
        func=_store, what="status"
    )
    x = st.add_parser("downlink", help="TC[15,9] by time window, TC[15,28] by sequence range")
    x.add_argument("store", type=int)
    x.add_argument("--from", dest="start", metavar="UTC")
    x.add_argument("--to", dest="end", metavar="UTC")
    x.add_argument("--first", type=int, help="first packet sequence count")
    x.add_argument("--last", type=int, help="last packet sequence count")
    x.set_defaults(func=_store, what="downlink")
    x = st.add_parser("delete-before", help="TC[15,11] delete content up to a time")
    x.add_argument("time", metavar="UTC")
    x.add_argument("stores", type=int, nargs="*", metavar="STORE")
    x.set_defaults(func=_store, what="delete-before")


_SUBTYPE = {"enable": 1, "disable": 2, "summary": 12}


def _utc(text):
    try:
        return parse_utc(text)
    except ValueError:
        raise UserError("time %r" % text, expected="UTC as YYYY-MM-DDTHH:MM:SS[.fff]Z") from None


def _pair(text, what):
    name, sep, value = text.rpartition(":")
    try:
        return name, int(value)
    except ValueError:
        raise UserError("%s %r" % (what, text), expected="NAME:NUMBER") from None


def _types(words):
    """{apid: {service: [subtypes]}} from APID[:SERVICE[:SUBTYPE]] words ({} for all)."""
    out = {}
    for w in words:
        try:
            parts = [int(p, 0) for p in w.split(":")]
        except ValueError:
            raise UserError("report type %r" % w, expected="APID[:SERVICE[:SUBTYPE]]") from None
        if not 1 <= len(parts) <= 3:
            raise UserError("report type %r" % w, expected="APID[:SERVICE[:SUBTYPE]]")
        services = out.setdefault(parts[0], {})
        if len(parts) > 1:
            subtypes = services.setdefault(parts[1], [])
            if len(parts) > 2:
                subtypes.append(parts[2])
    return out


def _stats(args):
    def go(g):
        sg = _storage(g)
        user = sg.statistics
        if args.what == "report":
            return sg.issue(user.report(g.apid, args.reset))
        if args.what == "reset":
            return sg.issue(user.reset(g.apid))
        if args.what == "add":
            items = dict(_pair(i, "statistics definition") for i in args.items)
            return sg.issue(user.add_definitions(g.apid, items))
        if args.what == "enable":
            return sg.issue(user.enable_periodic(g.apid, args.interval))
        return sg.issue(user.disable_periodic(g.apid))

    return session.run(args, go)


def _store(args):
    if args.what == "downlink":
        by_time = args.start is not None or args.end is not None
        by_count = args.first is not None or args.last is not None
        if by_time == by_count or (by_time and None in (args.start, args.end)):
            raise UserError(
                "store downlink needs one window",
                expected="--from UTC --to UTC, or --first N --last M",
            )
        if by_time:
            start, end = _utc(args.start), _utc(args.end)
    if args.what == "delete-before":
        until = _utc(args.time)

    def go(g):
        sg = _storage(g)
        what = args.what
        if what == "create":
            kw = {"kind": 1 if args.bounded else 0}
            if args.vc is not None:
                kw["vc"] = args.vc
            return sg.create_store(args.store, args.size, **kw)
        if what == "add-types":
            return sg.store_types(args.store, _types(args.types))
        if what == "enable":
            return sg.enable_storage(args.stores)
        if what == "disable":
            return sg.disable_storage(args.stores)
        if what == "summary":
            return sg.summary(args.stores)
        if what == "status":
            return sg.store_status()
        if what == "delete-before":
            return sg.delete_content(until, args.stores)
        if args.first is not None:
            return sg.retrieve_sequence(args.store, args.first, args.last)
        return sg.retrieve_time(args.store, start, end)

    return session.run(args, go)


def _file(args):
    def go(g):
        sg = _storage(g)
        files, apid = sg.files, g.apid
        if args.what == "copy":
            return sg.copy(args.source, args.target, move=args.move)[1]
        if args.what == "find":
            return sg.find(args.repository, args.pattern)
        if args.what == "attributes":
            return sg.attributes(args.path)
        if args.what == "delete":
            return sg.delete_file(args.path)
        if args.what == "create":
            return sg.issue(files.create(apid, args.path, args.max_size))
        if args.what == "mkdir":
            return sg.issue(files.create_directory(apid, args.path))
        return sg.issue(files.delete_directory(apid, args.path))

    return session.run(args, go)


def _large(args):
    """The TC SERVICE SUBTYPE DATA, sent in parts of service 13; the inner TC's reports."""
    if args.file:
        with open(args.file, "rb") as f:
            data = f.read()
    else:
        try:
            data = bytes.fromhex(args.data)
        except ValueError:
            raise UserError("application data %r" % args.data, expected="hex octets") from None
    for what, value in (("service", args.service), ("subtype", args.subtype)):
        if not 0 <= value <= 255:
            raise UserError("%s %d" % (what, value), expected="0 to 255")
    if args.part_size < 1:
        raise UserError("part size %d" % args.part_size, expected="at least 1 octet")

    def go(g):
        sg = _storage(g)
        sg.large.part_size = args.part_size
        from obsw.pus.services.schedule_user import embed

        raw, inner = embed(g.proc, g.apid, args.service, args.subtype, data)
        for part in sg.large.uplink(g.apid, raw):
            sg.issue(part)
            if not part.ok:
                return part  # the part's failure report says why
        return g.wait(inner)

    return session.run(args, go)


# ------------------------------------------------------------------------------ tc by name


def checked(field, value, what, valid=None):
    """``value`` if its type ``field`` can carry it and it is within ``valid`` ([low, high],
    the database's range), else UserError: nothing wrong is sent."""
    try:
        field.pack(value)
    except (ValueError, TypeError) as e:
        raise UserError("%s = %r: %s" % (what, value, e)) from None
    if valid and not isinstance(value, bool) and isinstance(value, (int, float)):
        low, high = valid
        if (low is not None and value < low) or (high is not None and value > high):
            raise UserError(
                "%s = %s is outside the database's range" % (what, value),
                expected="%s to %s" % (low, high),
            )
    return value


def tc_by_name(args):
    """`obsw ground tc FUNCTION ARG=VALUE..` or `tc PARAMETER=VALUE..`, checked first."""
    words = [args.what] + list(args.rest)

    def go(g):
        sdb = g.sdb
        if "=" in args.what:
            values = {}
            for name, value in session.assignments(words).items():
                p = sdb.parameter(name)
                if not p.writable:
                    raise UserError("parameter %s is read-only" % p.qualified)
                values[p.qualified] = checked(p.type, value, p.qualified, p.range)
            return g.set_parameters(values)
        fn = _function(sdb, args.what)
        given = {str(k): v for k, v in session.assignments(args.rest).items()}
        declared = {a[1]: a for a in fn.arguments}
        for name, value in given.items():
            if name not in declared:
                raise UserError(
                    "%s has no argument %r" % (fn.name, name),
                    expected=", ".join(declared) or "no arguments",
                )
            checked(field_type(declared[name][2]), value, "%s %s" % (fn.name, name))
        missing = [n for n, a in declared.items() if n not in given and a[3] is None]
        if missing:
            raise UserError("%s needs %s" % (fn.name, ", ".join(missing)), expected="ARG=VALUE")
        return g.perform(fn.name, **given)

    return session.run(args, go)


def _function(sdb, name):
    for fn in sdb.functions.values():
        if fn.name == name:
            return fn
    raise UserError(
        "no function or parameter assignment %r" % name,
        expected="one of `obsw ground list functions`, or PARAMETER=VALUE",
    )


def _storage(g):
    """The storage services' user (services 15, 23, ...), imported only for those commands."""
    from obsw_host.pus.storage_ground import StorageGround

    return StorageGround(g)
