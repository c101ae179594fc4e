"""`obsw ground memory|store|sequence|position`: the operator's commands of services 6 and 15
(copy, diagnostic storage control), and loading sequences by reference (21), the orbit (22).

    obsw ground memory dump 1 0x08000000 64                 TC[6,5]
    obsw ground memory dump 1 0x08000000 4096 --to SAT:/dumps/boot.bin      TC[6,20]
    obsw ground memory load 1 0x08000010 cafe01 [--atomic]  TC[6,2] (TC[6,11])
    obsw ground memory check 1 0x08000000 65536             TC[6,9]
    obsw ground memory load-file 1 0x08000000 SAT:/up/patch.bin --local patch.bin   TC[6,19]
    obsw ground memory dump 1 16 8 --object 2               TC[6,3]: object 2, offset 16
    obsw ground memory check-object 1 2                     TC[6,17]
    obsw ground memory abort-dumps                          TC[6,12]
    obsw ground memory scrub 1 on|off                       TC[6,13] / TC[6,14]
    obsw ground memory protect 1 on|off                     TC[6,15] / TC[6,16]
    obsw ground store copy 1 2 --from 2030-01-01T00:00:00Z --to 2030-01-01T01:00:00Z  TC[15,24]
    obsw ground store diag add|delete 1 5 6 | diag list 1   TC[15,31] / [15,32] / [15,37]
    obsw ground sequence file warmup.seq "0 ping" "2 function SolarPanel.deploy"   (no TC)
    obsw ground sequence load-file warmup SAT:/seq/warmup.seq [--activate]   TC[21,2] / [21,8]
    obsw ground position orbit 1234                         TC[22,28]

Addresses and lengths take 0x prefixes; with ``--object ID`` the address is an offset in that
object (object 0: the whole memory). Times are UTC (``...Z``) or on-board seconds.
"""

import argparse
import shlex

from obsw.crc import crc16_ccitt
from obsw.utc import parse_utc

from obsw_host.commands import session
from obsw_host.errors import UserError


def _number(text):
    try:
        return int(text, 0)
    except ValueError:
        raise argparse.ArgumentTypeError(
            "%r: expected an integer like 4096 or 0x1000" % text
        ) from None


def _hex(text):
    try:
        return bytes.fromhex(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            "%r: expected hexadecimal octets like cafe01" % text
        ) from None


def _time(text):
    try:
        return float(text)
    except ValueError:
        pass
    try:
        return parse_utc(text)
    except ValueError:
        expected = "YYYY-MM-DDTHH:MM:SS[.fff]Z or on-board seconds"
        raise argparse.ArgumentTypeError("%r: expected %s" % (text, expected)) from None


def add_to_ground(s):
    """``obsw ground memory ..`` and ``obsw ground store ..`` on the ground's subparsers."""
    me = s.add_parser("memory", help="service 6 memory management").add_subparsers(dest="mem")
    me.required = True
    for action, helptext in (
        ("dump", "TC[6,5] (--object: TC[6,3]; --to PATH: TC[6,20] / TC[6,22])"),
        ("check", "TC[6,9] (--object: TC[6,7])"),
    ):
        x = me.add_parser(action, help=helptext)
        x.add_argument("memory", type=_number)
        x.add_argument("address", type=_number, help="address, or offset with --object")
        x.add_argument("length", type=_number)
        x.add_argument("--object", type=_number, help="object ID: object memory")
        if action == "dump":
            x.add_argument("--to", metavar="PATH", help="dump into this on-board file")
        x.set_defaults(func=_memory_range, what=action)
    x = me.add_parser("load", help="TC[6,2] (--object: TC[6,1]; --atomic: TC[6,11])")
    x.add_argument("memory", type=_number)
    x.add_argument("address", type=_number, help="address, or offset with --object")
    x.add_argument("data", type=_hex, help="hexadecimal octets")
    how = x.add_mutually_exclusive_group()
    how.add_argument("--object", type=_number, help="object ID: object memory")
    how.add_argument("--atomic", action="store_true", help="whole or not at all")
    x.set_defaults(func=_memory_load)
    x = me.add_parser("load-file", help="TC[6,19] (--object: TC[6,21]): data from a file")
    x.add_argument("memory", type=_number)
    x.add_argument("address", type=_number, help="address, or offset with --object")
    x.add_argument("path", help="on-board file, e.g. SAT:/up/patch.bin")
    x.add_argument("--object", type=_number, help="object ID: object memory")
    sums = x.add_mutually_exclusive_group(required=True)
    sums.add_argument("--local", metavar="FILE", help="a local copy: its CRC-16 is sent")
    sums.add_argument("--checksum", type=_number, help="CRC-16/CCITT-FALSE of the file")
    x.set_defaults(func=_memory_load_file)
    x = me.add_parser("check-object", help="TC[6,17] checksum of a whole object")
    x.add_argument("memory", type=_number)
    x.add_argument("object", type=_number)
    x.set_defaults(func=_memory_call, call="check_whole_object")
    me.add_parser("abort-dumps", help="TC[6,12]").set_defaults(func=_memory_abort)
    for action, on, off in (
        ("scrub", "enable_scrubbing", "disable_scrubbing"),
        ("protect", "protect", "unprotect"),
    ):
        x = me.add_parser(action, help="TC[6,%s]" % ("13/14" if action == "scrub" else "15/16"))
        x.add_argument("memory", type=_number)
        x.add_argument("state", choices=("on", "off"))
        x.set_defaults(func=_memory_switch, on=on, off=off)

    st = s.add_parser("store", help="service 15: copy by time window, diagnostic storage")
    st = st.add_subparsers(dest="store")
    st.required = True
    x = st.add_parser("copy", help="TC[15,24] copy a time window into an empty store")
    x.add_argument("source", type=_number)
    x.add_argument("target", type=_number)
    x.add_argument("--from", dest="start", type=_time, help="UTC or on-board seconds")
    x.add_argument("--to", dest="end", type=_time, help="UTC or on-board seconds")
    x.set_defaults(func=_store_copy)
    diag = st.add_parser("diag", help="diagnostic report storage control").add_subparsers(
        dest="diag"
    )
    diag.required = True
    for action in ("add", "delete"):
        x = diag.add_parser(action, help="TC[15,%d]" % (31 if action == "add" else 32))
        x.add_argument("store", type=_number)
        x.add_argument("sids", type=_number, nargs="*", help="none: every structure")
        x.set_defaults(func=_store_diag, what=action)
    x = diag.add_parser("list", help="TC[15,37]")
    x.add_argument("store", type=_number)
    x.set_defaults(func=_store_diag, what="list")


def add_to_sequence(se):
    """``obsw ground sequence file|load-file`` on the sequence command's subparsers."""
    x = se.add_parser("file", help="write a sequence file for load-file (no TC is sent)")
    x.add_argument("out", metavar="FILE")
    x.add_argument("steps", nargs="+", help='"DELAY REQUEST.."')
    x.set_defaults(func=_sequence_file)
    x = se.add_parser("load-file", help="TC[21,2] (--activate: TC[21,8]) from an on-board file")
    x.add_argument("name")
    x.add_argument("path", help="on-board file, e.g. SAT:/seq/warmup.seq")
    x.add_argument("--activate", action="store_true")
    x.set_defaults(func=_sequence_load_file)


def add_to_position(sp):
    """``obsw ground position orbit N`` on the position command's subparsers."""
    x = sp.add_parser("orbit", help="TC[22,28] set the orbit number")
    x.add_argument("orbit", type=_number)
    x.set_defaults(func=_orbit)


# ------------------------------------------------------------------------------ service 6


def _storage(g):
    from obsw_host.pus.storage_ground import StorageGround

    return StorageGround(g)


def _memory_range(args):
    def go(g):
        sg = _storage(g)
        m = sg.memory
        rng = [(args.address, args.length)]
        if args.what == "check":
            if args.object is None:
                return sg.issue(m.check(g.apid, args.memory, rng))
            return sg.issue(m.check_object(g.apid, args.memory, args.object, rng))
        if args.to:
            item = [(args.address, args.length, args.to)]
            if args.object is None:
                return sg.issue(m.dump_to_file(g.apid, args.memory, item), _long(g))
            return sg.issue(
                m.dump_object_to_file(g.apid, args.memory, args.object, item), _long(g)
            )
        if args.object is None:
            return sg.issue(m.dump(g.apid, args.memory, rng))
        return sg.issue(m.dump_object(g.apid, args.memory, args.object, rng))

    return session.run(args, go)


def _long(g):
    return max(g.timeout, 60.0)  # a dump to file completes when the whole file is written


def _memory_load(args):
    def go(g):
        sg = _storage(g)
        m = sg.memory
        if args.atomic:
            return sg.issue(m.load_atomic(g.apid, args.memory, args.address, args.data))
        if args.object is not None:
            tx = m.load_object(g.apid, args.memory, args.object, args.address, args.data)
            return sg.issue(tx)
        return sg.issue(m.load(g.apid, args.memory, args.address, args.data))

    return session.run(args, go)


def _memory_load_file(args):
    if args.local:
        try:
            with open(args.local, "rb") as f:
                checksum = crc16_ccitt(f.read())
        except OSError as e:
            raise UserError("local file %s: %s" % (args.local, e.strerror)) from None
    else:
        checksum = args.checksum

    def go(g):
        sg = _storage(g)
        m = sg.memory
        item = [(args.address, args.path, checksum)]
        if args.object is None:
            return sg.issue(m.load_by_reference(g.apid, args.memory, item))
        return sg.issue(m.load_object_by_reference(g.apid, args.memory, args.object, item))

    return session.run(args, go)


def _memory_call(args):
    def go(g):
        sg = _storage(g)
        return sg.issue(getattr(sg.memory, args.call)(g.apid, args.memory, args.object))

    return session.run(args, go)


def _memory_abort(args):
    def go(g):
        sg = _storage(g)
        return sg.issue(sg.memory.abort_dumps(g.apid))

    return session.run(args, go)


def _memory_switch(args):
    def go(g):
        sg = _storage(g)
        fn = getattr(sg.memory, args.on if args.state == "on" else args.off)
        return sg.issue(fn(g.apid, args.memory))

    return session.run(args, go)


# ------------------------------------------------------------------------------ service 15


def _store_copy(args):
    if args.start is None and args.end is None:
        raise UserError("store copy without a time window", expected="--from, --to or both")

    def go(g):
        sg = _storage(g)
        return sg.issue(
            sg.storage.copy_window(g.apid, args.source, args.target, args.start, args.end)
        )

    return session.run(args, go)


def _store_diag(args):
    def go(g):
        sg = _storage(g)
        u = sg.storage
        if args.what == "list":
            return sg.issue(u.report_diag(g.apid, args.store))
        fn = u.add_diag if args.what == "add" else u.delete_diag
        return sg.issue(fn(g.apid, args.store, {g.apid: list(args.sids)}))

    return session.run(args, go)


# ------------------------------------------------------------------------------ 21 and 22


def _sequence_file(args):
    with session.ground(args) as g:
        session.fresh(g)
        items = []
        for step in args.steps:
            words = shlex.split(step)
            try:
                delay = float(words[0])
            except (ValueError, IndexError):
                raise UserError("sequence step %r" % step, expected="'DELAY REQUEST..'") from None
            items.append((session.request(g, words[1:]), delay))
        data = g.sequencing.sequence_file(items)
    try:
        with open(args.out, "wb") as f:
            f.write(data)
    except OSError as e:
        raise UserError("cannot write %s: %s" % (args.out, e.strerror)) from None
    print(
        "%s: %d requests, %d octets; upload it, then `sequence load-file`"
        % (args.out, len(items), len(data))
    )
    return 0


def _sequence_load_file(args):
    def go(g):
        u = g.sequencing
        fn = u.load_and_activate if args.activate else u.load_by_reference
        return g.issue(fn(g.apid, args.name, args.path))

    return session.run(args, go)


def _orbit(args):
    return session.run(args, lambda g: g.issue(g.position.set_orbit(g.apid, args.orbit)))
