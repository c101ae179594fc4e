"""`obsw spacecan`: a bus monitor, a simulated responder node, a ping and
the OBC's master with its equipment components on the interaction layer."""


def add_parser(sub):
    p = sub.add_parser("spacecan", help="SpaceCAN bus tools", description=__doc__)
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True

    def bus_args(q):
        q.add_argument(
            "--interface",
            default="virtual",
            help="python-can interface: socketcan, udp_multicast, virtual",
        )
        q.add_argument("--channel-a", default="can0", help="bus A (nominal) channel")
        q.add_argument("--channel-b", default="can1", help="bus B (redundant) channel")
        q.add_argument("--duration", type=float, default=None, help="stop after this many s")
        q.add_argument("--node-def", help="node definition JSON (spacecan's services file)")

    m = s.add_parser("monitor", help="print the frames on both buses, decoded")
    bus_args(m)
    m.add_argument("--node-id", type=int, default=1, help="node the --node-def describes")
    m.set_defaults(func=monitor)

    r = s.add_parser("responder", help="run a responder node serving a node definition")
    bus_args(r)
    r.add_argument("--node-id", type=int, required=True)
    r.add_argument("--heartbeat-period", type=float, default=0.5)
    r.set_defaults(func=responder)

    ms = s.add_parser(
        "master",
        help="serve the SpaceCAN master and equipment components to other processes",
        description="The OBC side: SpaceCanMaster and one equipment component per node "
        "(attributes fed by housekeeping, operations mapped to service 8 functions), served "
        "on the interaction layer; other processes use them through proxies.",
    )
    from obsw_host.spacecan import obc

    obc.add_arguments(ms)
    ms.set_defaults(func=master)

    g = s.add_parser("ping", help="run a controller and ping a node (17,1)")
    bus_args(g)
    g.add_argument("--node-id", type=int, required=True)
    g.add_argument("--count", type=int, default=1)
    g.set_defaults(func=ping)


def master(args):
    from obsw_host.spacecan import obc

    return obc.run(args)


def _nodedef(path, node_id):
    from obsw.spacecan.nodedef import NodeDefinition

    if path is None:
        return NodeDefinition((), (), (), node_id)
    return NodeDefinition.load(path, node_id)


def _until(args):
    import time

    end = None if args.duration is None else time.monotonic() + args.duration
    try:
        while end is None or time.monotonic() < end:
            time.sleep(0.05)
    except KeyboardInterrupt:
        pass


def monitor(args):
    import queue
    import time

    import can

    from obsw_host.spacecan.monitor import Monitor

    nodes = {}
    if args.node_def:
        nodes[args.node_id] = _nodedef(args.node_def, args.node_id)
    mon = Monitor(nodes)
    buses = [
        can.Bus(interface=args.interface, channel=ch) for ch in (args.channel_a, args.channel_b)
    ]
    q = queue.Queue()
    notifier = can.Notifier(buses, [lambda msg: q.put(msg)], timeout=0.05)
    t0 = time.monotonic()
    end = None if args.duration is None else t0 + args.duration
    try:
        while end is None or time.monotonic() < end:
            try:
                msg = q.get(timeout=0.1)
            except queue.Empty:
                continue
            bus = 0 if msg.channel in (None, args.channel_a) else 1
            for line in mon.lines(bus, msg.arbitration_id, msg.data, time.monotonic() - t0):
                print(line, flush=True)
    except KeyboardInterrupt:
        pass
    finally:
        notifier.stop()
        for b in buses:
            b.shutdown()
    return 0


def responder(args):
    from obsw.spacecan.responder import Responder

    from obsw_host.spacecan.adapter import CanAdapter

    node = Responder(
        args.node_id, _nodedef(args.node_def, args.node_id), heartbeat_period=args.heartbeat_period
    )
    node.on_function = lambda fid, fargs: print("function %d %r" % (fid, fargs), flush=True)
    ad = CanAdapter(node, interface=args.interface, channels=(args.channel_a, args.channel_b))
    ad.subscribe(lambda e: print(e, flush=True))
    with ad:
        print(
            "responder node %d on %s %s/%s"
            % (args.node_id, args.interface, args.channel_a, args.channel_b),
            flush=True,
        )
        _until(args)
    return 0


def ping(args):
    from obsw.spacecan.controller import Controller

    from obsw_host.spacecan.adapter import CanAdapter

    ctrl = Controller()
    ctrl.add_node(args.node_id, _nodedef(args.node_def, args.node_id) if args.node_def else None)
    failed = 0
    with CanAdapter(
        ctrl, interface=args.interface, channels=(args.channel_a, args.channel_b)
    ) as ad:
        for _ in range(args.count):
            req = ad.request(lambda now: ctrl.ping(args.node_id, now))
            print(
                "ping node %d: %s (%d attempts, bus %s)"
                % (args.node_id, req.status, req.attempts, "AB"[req.bus]),
                flush=True,
            )
            failed += not req.ok
    return 1 if failed else 0
