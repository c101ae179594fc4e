"""What the `obsw ground` commands share: a ``Ground`` for the mission (``ground``), a
request run and its result printed (``run``), TM listened for (``listen``), and the request a
command line names (``request``, ``assignments``)."""

import json
import sys

from obsw_host.errors import UserError
from obsw_host.mission import ids as mission_ids


def ground(args):
    from obsw_host.pus.ground import Ground
    from obsw_host.pus.monitor import SessionLog

    ids = mission_ids.from_args(args)
    apid = args.apid if args.apid is not None else ids.pus_apid
    target = (args.host, pus_port(args, ids, apid))
    log = (lambda s: print(s, file=sys.stderr)) if args.verbose else None
    session = SessionLog(args.log) if getattr(args, "log", None) else None
    g = Ground(
        ids.sdb,
        apid=apid,
        target=target,
        timeout=args.timeout,
        log=log,
        session=session,
        source_id=ids.source_id,
        config=ids.pus_config,
    )
    return fresh(g)


def pus_port(args, ids, apid):
    """The on-board UDP port: ``--port``, else the mission's port of process ``apid``."""
    if args.port is not None:
        return args.port
    return ids.ports.for_apid(apid)


def run(args, fn):
    from obsw_host.pus import display, text
    from obsw_host.pus.ground import PusTimeout

    with ground(args) as g:
        try:
            tx = fn(g)
        except PusTimeout as e:
            tx = e.transaction
        sdb = g.sdb
        target = g.target
    result = text.transaction(tx)
    detail = display.failure_detail(tx, sdb)  # the component's error by name
    if args.json:
        if detail:
            result["failure_detail"] = detail
        print(json.dumps(result))
        return 0 if tx.ok else 1
    for line in tx.verification():
        if "failure" in line and detail:  # the data decoded replaces its hex
            line = "%s (%s)" % (line.split(" data ")[0], detail)
        print("  " + line)
    for reply in tx.replies:
        print(display.readable(reply, sdb, getattr(args, "raw", False)))  # names, tables
    if not tx.done:
        print(no_answer(args, tx, target))
    return 0 if tx.ok else 1


def no_answer(args, tx, target):
    if not tx.verification():
        return "no report from %s:%s within %ss: is `obsw obc serve` running there?" % (
            target[0],
            target[1],
            args.timeout,
        )
    return "no completion report within %ss" % args.timeout


def listen(args):
    """Print TM of one type for a while (subscribed: TM caused by any client comes too)."""
    import time

    from obsw_host.pus import text
    from obsw_host.pus.monitor import Display

    service, subtype = args.listen
    n = 0
    with ground(args) as g:
        display = Display(g.sdb, raw=getattr(args, "raw", False), config=g.proc.config)
        g.subscribe()
        print(
            "listening for TM[%s,%s] from %s:%d for %gs"
            % (service, subtype or "*", g.target[0], g.target[1], args.seconds),
            file=sys.stderr,
            flush=True,
        )
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
                        item = {"type": [tm.service, tm.subtype], "value": text.plain(decoded)}
                        print(json.dumps(item), flush=True)
                    else:
                        print(display.tm(tm, decoded), flush=True)
            seen = len(g.received)
    if not n:
        print("no TM[%s,%s] within %ss" % (service, subtype or "*", args.seconds), file=sys.stderr)
    return 0


def _learn(g, tm, decoded):
    """A report of a structure this ground has not seen: ask for its layout, decode again."""
    try:
        g.learn_structure(decoded["sid"], kind=g.hk.kind_of(tm))
        return g.hk.decode_report(tm)
    except Exception:
        return decoded


def fresh(g):
    """Sequence counts that differ from an earlier run's, so request IDs stay unique."""
    import time

    from obsw.spp import SequenceCounter

    g.proc.sequence = SequenceCounter(int(time.time() * 16) & 0x3FFF)
    return g


def assignments(words):
    out = {}
    for w in words:
        name, sep, text = w.partition("=")
        if not sep:
            raise UserError("assignment %r" % w, expected="NAME=VALUE")
        out[key(name)] = value(text)
    return out


def key(text):
    return int(text) if text.isdigit() else text


def value(text):
    try:
        return json.loads(text)
    except ValueError:
        return text


def request(g, words):
    """The on-board request a command line names (a Transaction, not sent)."""
    kind = words[0] if words else ""
    if kind == "ping" and len(words) == 1:
        return g.request(17, 1)
    if kind == "function" and len(words) >= 2:
        args = {str(k): v for k, v in assignments(words[2:]).items()}
        return g.function_request(key(words[1]), **args)
    if kind == "set" and len(words) >= 2:
        return g.parameter_request(assignments(words[1:]))
    if kind == "service" and len(words) >= 3:
        return mission_call(g.service_request, words[1], words[2], words[3:])
    raise UserError(
        "request %r" % " ".join(words),
        expected="ping | function NAME [ARG=VALUE..] | service NAME REQUEST [ARG=VALUE..] | "
        "set NAME=VALUE..",
    )


def mission_call(method, service, request, words):
    """``method(service, request, **arguments)`` with mistakes in the names, types or ranges
    of the arguments said as the user's."""
    from obsw.pus.services.mission import MissionArgumentError

    values = {str(k): v for k, v in assignments(words).items()}
    try:
        return method(key(service), key(request), **values)
    except KeyError as e:
        raise UserError(str(e.args[0]) if e.args else str(e)) from None
    except MissionArgumentError as e:
        raise UserError(str(e)) from None
