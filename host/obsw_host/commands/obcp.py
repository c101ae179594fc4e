"""`obsw obcp` (also `obsw ground obcp`): PLUTO OBCPs on board through PUS service 18.

    obsw obcp serve [--files DIR]           on-board process with service 18, the OBCP engine
                                            and the solar panel (UDP base + APID)
    obsw obcp load NAME FILE [--arg N=V]..  upload a procedure (TC[18,1]); --arg declares an
                                            argument with its default value (V: JSON or text,
                                            "30 deg" for a quantity)
    obsw obcp load-ref NAME REPO FILE       load a file of the on-board filestore (TC[18,13])
    obsw obcp activate NAME [--arg N=V].. [--level 0-3]          (TC[18,3])
    obsw obcp stop|suspend|resume|abort|unload|stop-unload NAME  (TC[18,4|5|6|12|2|20])
    obsw obcp step-activate NAME [--arg N=V].. [--level 0-3]
                                            activate and execute one step (TC[18,14])
    obsw obcp step NAME                     resume and execute one step (TC[18,15])
    obsw obcp answer NAME VALUE             the answer to an OBCP's question (TC[18,7])
    obsw obcp observe NAME LEVEL            observability 0 none .. 3 statement (TC[18,16])
    obsw obcp status                        every OBCP's status (TC[18,8] -> TM[18,9])
    obsw obcp abort-all                     (TC[18,17] -> TM[18,18])
    obsw obcp engine start|stop             (TC[18,21] / TC[18,22])
    obsw obcp listen [--seconds S]          OBCP events (service 5) as they come

``--json`` prints one JSON object per command instead of text; ``-v`` shows every packet.
"""

import json
import os
import sys
import threading

from obsw_host.commands import session
from obsw_host.mission import ids as mission_ids
from obsw_host.net import DEFAULT_HOST

_SIMPLE = {
    "stop": "stop",
    "suspend": "suspend",
    "resume": "resume",
    "abort": "abort",
    "unload": "unload",
    "stop-unload": "stop_and_unload",
}


def add_parser(sub):
    """``obsw obcp ...``: the client actions, plus ``serve``."""
    p = sub.add_parser(
        "obcp", help="PLUTO OBCPs on board (PUS service 18)", description=__doc__,
        formatter_class=_raw(),
    )  # fmt: skip
    add_client_options(p)
    s = p.add_subparsers(dest="obcp", metavar="ACTION")
    s.required = True
    add_actions(s)
    x = s.add_parser("serve", help="serve an on-board process with service 18 until Ctrl-C")
    x.add_argument("--files", help="filestore folder for loads by reference")
    x.add_argument("--period", type=float, default=0.1, help="activity loop cycle, seconds")
    x.set_defaults(func=_serve)


def add_to_ground(ground_actions):
    """``obsw ground obcp ...``: call with the ``ground`` command's subparsers (its client
    options --mission, --sdb, --host, --port, --apid, --timeout, --json and -v are used)."""
    p = ground_actions.add_parser(
        "obcp", help="service 18 OBCPs", description=__doc__, formatter_class=_raw()
    )
    s = p.add_subparsers(dest="obcp", metavar="ACTION")
    s.required = True
    add_actions(s)


def add_client_options(p):
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


def add_actions(s):
    x = s.add_parser("load", help="TC[18,1] upload a procedure file")
    x.add_argument("name")
    x.add_argument("file")
    x.add_argument("--arg", action="append", default=[], metavar="NAME=VALUE")
    x.set_defaults(func=_load)
    x = s.add_parser("load-ref", help="TC[18,13] load a file of the on-board filestore")
    x.add_argument("name")
    x.add_argument("repository")
    x.add_argument("file")
    x.add_argument("--arg", action="append", default=[], metavar="NAME=VALUE")
    x.set_defaults(func=_load_ref)
    x = s.add_parser("activate", help="TC[18,3] activate an OBCP")
    x.add_argument("name")
    x.add_argument("--arg", action="append", default=[], metavar="NAME=VALUE")
    x.add_argument("--level", type=int, default=2, help="observability 0..3 (default 2)")
    x.set_defaults(func=_activate)
    x = s.add_parser("step-activate", help="TC[18,14] activate and execute one step")
    x.add_argument("name")
    x.add_argument("--arg", action="append", default=[], metavar="NAME=VALUE")
    x.add_argument("--level", type=int, default=2, help="observability 0..3 (default 2)")
    x.set_defaults(func=_step_activate)
    x = s.add_parser("step", help="TC[18,15] resume a suspended OBCP for one step")
    x.add_argument("name")
    x.set_defaults(func=_step)
    for action in _SIMPLE:
        x = s.add_parser(action, help="%s an OBCP" % action.replace("-", " and "))
        x.add_argument("name")
        x.set_defaults(func=_simple, action_name=action)
    x = s.add_parser("answer", help="TC[18,7] answer an OBCP's question")
    x.add_argument("name")
    x.add_argument("value")
    x.set_defaults(func=_answer)
    x = s.add_parser("observe", help="TC[18,16] set an OBCP's observability level")
    x.add_argument("name")
    x.add_argument("level", type=int)
    x.set_defaults(func=_observe)
    s.add_parser("status", help="TC[18,8] status of each OBCP").set_defaults(func=_status)
    s.add_parser("abort-all", help="TC[18,17] abort every OBCP").set_defaults(func=_abort_all)
    x = s.add_parser("engine", help="TC[18,21|22] start or stop the OBCP engine")
    x.add_argument("what", choices=("start", "stop"))
    x.set_defaults(func=_engine)
    x = s.add_parser("listen", help="print OBCP events as they come")
    x.add_argument("--seconds", type=float, default=5.0)
    x.set_defaults(func=_listen)


def _raw():
    import argparse

    return argparse.RawDescriptionHelpFormatter


def _port(args, ids, apid):
    """``--port``, else the mission's UDP port of process ``apid``."""
    if args.port is not None:
        return args.port
    return ids.ports.for_apid(apid)


def _client(args):
    from obsw_host.pus.ground import Ground
    from obsw_host.pus.obcp_ground import ObcpGround

    ids = mission_ids.from_args(args)
    apid = args.apid if args.apid is not None else ids.pus_apid
    target = (args.host, _port(args, ids, apid))
    log = (lambda s: print(s, file=sys.stderr)) if args.verbose else None
    ground = Ground(
        ids.sdb,
        apid=apid,
        target=target,
        timeout=args.timeout,
        log=log,
        source_id=ids.source_id,
        config=ids.pus_config,
    )
    return ground, ObcpGround(ground)


def parse_value(text):
    """A command-line value: JSON if it parses, ``"<number> <unit>"`` as a quantity, else
    the text itself."""
    try:
        return json.loads(text)
    except ValueError:
        pass
    number, _, unit = text.partition(" ")
    try:
        return {"value": float(number), "unit": unit.strip()} if unit.strip() else text
    except ValueError:
        return text


def parse_arguments(pairs):
    out = {}
    for a in pairs:
        name, sep, value = a.partition("=")
        if not sep or not name:
            raise ValueError("expected NAME=VALUE, got %r" % a)
        out[name] = parse_value(value)
    return out


def _run(args, fn):
    from obsw_host.pus import text
    from obsw_host.pus.ground import PusTimeout
    from obsw_host.pus.obcp_ground import explain

    ground, obcp = _client(args)  # bad input: typed errors, one line from obsw_host.cli
    _session(ground, args)
    with ground:
        try:
            tx = fn(obcp)
        except PusTimeout as e:
            tx = e.transaction
    if args.json:
        result = text.plain(text.transaction(tx))
        result["explained"] = explain(tx)
        print(json.dumps(result))
    else:
        lines = explain(tx)
        if not tx.done:  # the same line as every `obsw ground` command: who did not answer
            lines[-1] = session.no_answer(args, tx, ground.target)
        for line in lines:
            print("  " + line)
        for reply in tx.replies:
            _print_reply(reply)
    return 0 if tx.ok else 1


def _session(ground, args):
    """Sequence counts that differ from an earlier run's (unique request IDs), and the
    session log of ``--log`` (also `obsw ground --log .. obcp`)."""
    from obsw_host.pus.monitor import SessionLog

    session.fresh(ground)
    if getattr(args, "log", None):
        ground.session = SessionLog(args.log)


def _print_reply(reply):
    if "obcps" in reply:
        if not reply["obcps"]:
            print("no OBCPs loaded")
        for o in reply["obcps"]:
            extra = ""
            if "outcome" in o:
                extra = " (last outcome %s, %d activations, line %d%s)" % (
                    o["outcome"],
                    o["activations"],
                    o["line"],
                    ", step " + o["step"] if o["step"] else "",
                )
            print("%-16s %s%s" % (o["id"], o["status"], extra))
    elif "ids" in reply:
        print("aborted: %s" % (", ".join(reply["ids"]) or "none"))
    else:
        print(json.dumps(reply))


def _load(args):
    arguments = parse_arguments(args.arg)
    return _run(args, lambda o: o.load_file(args.name, args.file, arguments or None))


def _load_ref(args):
    arguments = parse_arguments(args.arg)
    return _run(
        args,
        lambda o: o.load_by_reference(args.name, args.repository, args.file, arguments or None),
    )


def _activate(args):
    arguments = parse_arguments(args.arg)
    return _run(args, lambda o: o.activate(args.name, arguments or None, args.level))


def _step_activate(args):
    arguments = parse_arguments(args.arg)
    return _run(args, lambda o: _until_held(
        o, args, o.activate_and_step(args.name, arguments or None, args.level)))  # fmt: skip


def _step(args):
    return _run(args, lambda o: _until_held(o, args, o.resume_and_step(args.name)))


def _until_held(o, args, tx):
    """A step request returns once the OBCP holds again (or has ended), so the next `step`
    finds it suspended."""
    if tx.ok:
        o.held(args.name, timeout=max(args.timeout, 10.0))
    return tx


def _simple(args):
    method = _SIMPLE[args.action_name]
    return _run(args, lambda o: getattr(o, method)(args.name))


def _answer(args):
    return _run(args, lambda o: o.answer(args.name, parse_value(args.value)))


def _observe(args):
    return _run(args, lambda o: o.set_observability({args.name: args.level}))


def _status(args):
    return _run(args, lambda o: o.report_status())


def _abort_all(args):
    return _run(args, lambda o: o.abort_all())


def _engine(args):
    return _run(args, lambda o: o.start_engine() if args.what == "start" else o.stop_engine())


def _listen(args):
    """Print OBCP events for a while (after a status request, so TM finds the way back)."""
    import time

    from obsw_host.pus import text

    ground, obcp = _client(args)
    n = 0
    with ground:
        try:
            obcp.report_status()
        except Exception as e:
            print("obsw obcp: on-board process does not answer: %s" % e, file=sys.stderr)
            return 1
        end = time.monotonic() + args.seconds
        while time.monotonic() < end:
            for name, data in obcp.events(timeout=min(0.2, max(0.0, end - time.monotonic()))):
                n += 1
                if args.json:
                    print(json.dumps({"event": name, "data": text.plain(data)}), flush=True)
                else:
                    print("%-13s %s" % (name, json.dumps(text.plain(data))), flush=True)
    if not n:
        print("no OBCP events within %gs" % args.seconds, file=sys.stderr)
    return 0


def _serve(args):
    from obsw_host.pus.obcp_onboard import onboard_with_obcp

    ids = mission_ids.from_args(args)
    apid = args.apid if args.apid is not None else ids.pus_apid
    onboard, engine = onboard_with_obcp(
        ids.sdb,
        files=args.files,
        apid=apid,
        host=args.host,
        port=_port(args, ids, apid),
        period=args.period,
    )
    onboard.start()  # bound (or OSError) before "serving" is printed
    print(
        "PUS application process APID %d with service 18 serving on udp %s:%d (Ctrl-C stops)"
        % (onboard.apid, onboard.host, onboard.address[1]),
        file=sys.stderr,
        flush=True,
    )
    try:
        threading.Event().wait()
    except KeyboardInterrupt:
        pass
    finally:
        onboard.stop()
        engine.abort_all("on-board process stopped")
        engine.system.close()
    return 0
