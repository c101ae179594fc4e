"""`obsw il`: serve, call, read, write and watch components over the interaction layer."""

import json
import sys

from obsw_host.obc.plugins import add_serve_arguments, serve_args


def add_parser(sub):
    p = sub.add_parser(
        "il", help="interaction layer: serve and use components", description=__doc__
    )
    p.add_argument("--dir", help="name directory (default $OBSW_IL_DIR or a per-user temp dir)")
    p.add_argument("--timeout", type=float, default=5.0, help="seconds per call (default 5)")
    p.add_argument("--retries", type=int, default=0, help="extra attempts per call")
    isub = p.add_subparsers(dest="il_command", metavar="ACTION")
    isub.required = True

    s = isub.add_parser("serve", help="provide a component (any plug-in module) in this process")
    add_serve_arguments(s)
    s.set_defaults(func=serve_args)

    c = isub.add_parser("call", help="call Component.operation with arguments (JSON or text)")
    c.add_argument("target")
    c.add_argument("args", nargs="*")
    c.set_defaults(func=_call)

    g = isub.add_parser("get", help="read Component.attribute")
    g.add_argument("target")
    g.set_defaults(func=_get)

    st = isub.add_parser("set", help="write Component.attribute")
    st.add_argument("target")
    st.add_argument("value")
    st.set_defaults(func=_set)

    w = isub.add_parser("watch", help="print publications of Component.member (or Component.*)")
    w.add_argument("target")
    w.add_argument("--count", type=int, default=0, help="stop after this many (0: never)")
    w.set_defaults(func=_watch)

    ls = isub.add_parser("list", help="components that are provided right now")
    ls.set_defaults(func=_list)


def _value(text):
    try:
        return json.loads(text)
    except ValueError:
        return text


def _user(args):
    from obsw.il.node import Node

    from obsw_host.il.transport import SocketTransport

    node = Node("obsw-il-cli")
    return node, SocketTransport(node, args.dir, listen=False)


def _run(args, action):
    from obsw.il.errors import InteractionError

    node, transport = _user(args)
    try:
        result = action(node)
    except InteractionError as e:
        code = getattr(e, "code", None)
        kind = type(e).__name__ + ("" if code is None else " " + str(code))
        data = "" if e.data is None else " (data %r)" % (e.data,)
        print("obsw il: %s: %s%s" % (kind, e, data), file=sys.stderr)
        return 1
    finally:
        transport.close()
    if result is not None:
        print(json.dumps(result, default=repr))
    return 0


def _call(args):
    from obsw.il.proxy import Pending

    def action(node):
        r = node.call(
            args.target,
            [_value(a) for a in args.args],
            timeout=args.timeout,
            retries=args.retries,
        )
        if isinstance(r, Pending):
            r = r.result(timeout=args.timeout)
        return r

    return _run(args, action)


def _get(args):
    return _run(
        args, lambda node: node.get(args.target, timeout=args.timeout, retries=args.retries)
    )


def _set(args):
    return _run(
        args,
        lambda node: node.set(
            args.target, _value(args.value), timeout=args.timeout, retries=args.retries
        ),
    )


def _watch(args):
    def action(node):
        sub = node.subscribe(args.target, timeout=args.timeout, length=64)
        n = 0
        while not args.count or n < args.count:
            pub = sub.receive(timeout=None)
            print("%s %s" % (pub.name, json.dumps(pub.value, default=repr)), flush=True)
            n += 1

    return _run(args, action)


def _list(args):
    from obsw_host.il.directory import Directory

    for name in Directory(args.dir).names():
        print(name)
    return 0
