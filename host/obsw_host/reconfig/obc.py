"""The OBC process of the reconfiguration simulation (CPython): SpaceCAN controller on the hub.

With ``--uart FD,FD`` (the OBC ends of the controllers' OBC UARTs) it first reads its onboard
time from the DS3231 and its context back from the safeguard memory through the module, then
sends heartbeats on the UARTs and saves its context every ``--context-period`` seconds (each
save logged: a test waits for the saves it needs).
It distributes its time (UTC and SCET frames), then runs the commands given with
``--call NODE:FUNCTION:VALUE`` (service 8 with one argument) all at once, prints each result
and keeps sending heartbeats until it is killed (or powered off through the CPDU).
"""

import argparse
import sys
import time

from obsw.reconfig.node import definition
from obsw.spacecan.controller import Controller

from obsw_host.obc.context import ObcContext
from obsw_host.reconfig.canhub import HubBus
from obsw_host.reconfig.link import ObcLink
from obsw_host.spacecan.adapter import CanAdapter

EPOCH_1958 = -4383 * 86400  # 1958-01-01 in Unix seconds
TM_APID = 0x100  # the APID whose sequence count the simulated OBC carries in its context


def utc_now():
    """(day since 1958-01-01, ms of day) of the host clock."""
    t = time.time()
    days = int(t // 86400) + 4383  # 1970-01-01 is day 4383 after 1958-01-01
    return days, int((t % 86400) * 1000)


def restore(link, line, say):
    """Onboard time and context at start: (ObcContext, obt offset from the host clock)."""
    rtc = link.read_time()
    ctx = link.read_context()
    if ctx is None:
        ctx = ObcContext()
        say("no context kept: a first start")
    else:
        say("context restored: %r" % ctx)
    if rtc is not None:
        obt = rtc[0] * 86400 + rtc[1] / 1000
        say("onboard time from the DS3231: day %d, %d ms" % rtc)
    else:  # the clock stopped: the saved time, late by the time spent off
        obt = ctx.obt
        say("DS3231 time invalid: onboard time from the context (coarse)")
    ctx.boots += 1
    ctx.mode = ctx.mode or 1
    return ctx, obt - time.time()


def main(argv=None):
    p = argparse.ArgumentParser(prog="obsw-reconfig-obc")
    p.add_argument("hub_a", type=int)
    p.add_argument("hub_b", type=int)
    p.add_argument("--call", action="append", default=[], help="NODE:FUNCTION:VALUE")
    p.add_argument("--nodes", help="NOMINAL,REDUNDANT node ids (default: the sample mission's)")
    p.add_argument("--uart", default="", help="file descriptors of the OBC UARTs: FD,FD")
    p.add_argument("--line", type=int, default=0, help="the CPDU line powering this OBC")
    p.add_argument("--boot-delay", type=float, default=0.0, help="simulated boot time (s)")
    p.add_argument("--heartbeat", type=float, default=0.2)
    p.add_argument("--context-period", type=float, default=1.0)
    args = p.parse_args(argv)

    def say(text):
        print("[OBC] " + text, flush=True)

    time.sleep(args.boot_delay)
    link = ObcLink(int(x) for x in args.uart.split(",")) if args.uart else None
    ctx, offset = (None, 0.0)
    if link is not None:
        ctx, offset = restore(link, args.line, say)
    ctrl = Controller(heartbeat_period=0.2, timeout=0.5, retries=3)
    if args.nodes is None:
        from obsw_host.mission.ids import MissionIds

        args.nodes = "%d,%d" % MissionIds.sample().reconfig_nodes
    for n in args.nodes.split(","):
        ctrl.add_node(int(n), definition(int(n)))
    adapter = CanAdapter(ctrl, buses=[HubBus(args.hub_a), HubBus(args.hub_b)])
    adapter.start()
    say("up on line %d, SpaceCAN controller on hub %d/%d" % (args.line, args.hub_a, args.hub_b))
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
    next_save = time.monotonic()
    try:
        while True:
            if link is None:
                time.sleep(1.0)
                continue
            link.heartbeat()
            ctx.seq[TM_APID] = (ctx.seq.get(TM_APID, 0) + 1) & 0x3FFF  # one TM per beat
            if time.monotonic() >= next_save:
                ctx.obt = time.time() + offset
                ctx.utc_at = time.time() - EPOCH_1958
                ctx.saves += 1
                kept = link.write_context(ctx, timeout=0.5)
                next_save = time.monotonic() + args.context_period
                say("context saved (save %d, %d controllers)" % (ctx.saves, kept))
            time.sleep(args.heartbeat)
    except KeyboardInterrupt:
        pass
    adapter.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
