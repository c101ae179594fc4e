"""The OBC process of the reconfiguration simulation (CPython): SpaceCAN controller on the hub.

At start it distributes its time (UTC and SCET frames), then runs the commands given with
``--call NODE:FUNCTION:VALUE`` (service 8 with one argument) all at once, prints each result
and keeps sending heartbeats until it is killed (or powered off through the CPDU).
"""

import argparse
import sys
import time


def utc_now():
    """(day since 1958-01-01, ms of day) of the host clock."""
    t = time.time()
    days = int(t // 86400) + 4383  # 1970-01-01 is day 4383 after 1958-01-01
    return days, int((t % 86400) * 1000)


def main(argv=None):
    from obsw.reconfig.node import definition
    from obsw.spacecan.controller import Controller

    from obsw_host.reconfig.canhub import HubBus
    from obsw_host.spacecan.adapter import CanAdapter

    p = argparse.ArgumentParser(prog="obsw-reconfig-obc")
    p.add_argument("hub_a", type=int)
    p.add_argument("hub_b", type=int)
    p.add_argument("--call", action="append", default=[], help="NODE:FUNCTION:VALUE")
    p.add_argument("--nodes", help="NOMINAL,REDUNDANT node ids (default: the sample mission's)")
    args = p.parse_args(argv)
    ctrl = Controller(heartbeat_period=0.2, timeout=0.5, retries=3)
    if args.nodes is None:
        from obsw_host.ids import MissionIds

        args.nodes = "%d,%d" % MissionIds.sample().reconfig_nodes
    for n in args.nodes.split(","):
        ctrl.add_node(int(n), definition(int(n)))
    adapter = CanAdapter(ctrl, buses=[HubBus(args.hub_a), HubBus(args.hub_b)])
    adapter.start()
    print("[OBC] up, SpaceCAN controller on hub %d/%d" % (args.hub_a, args.hub_b), flush=True)
    day, ms = utc_now()
    adapter.call(lambda now: ctrl.send_utc(day, ms, now=now))
    adapter.call(lambda now: ctrl.send_scet(int(time.time()) & 0xFFFFFFFF, now=now))
    print("[OBC] time sent: day %d, %d ms" % (day, ms), flush=True)
    pending = []
    for spec in args.call:
        node, fid, value = (int(x, 0) for x in spec.split(":"))
        req = adapter.call(
            lambda now, n=node, f=fid, v=value: ctrl.call_function(n, f, now=now, args={1: v})
        )
        pending.append((spec, req))
    for spec, req in pending:
        adapter.wait_for(lambda r=req: r.done, 10.0)
        print("[OBC] call %s -> %s" % (spec, req.status), flush=True)
    try:
        while True:
            time.sleep(1.0)
    except KeyboardInterrupt:
        pass
    adapter.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
