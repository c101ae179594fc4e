"""The OBCP engine in its own process on the interaction layer's socket transport.

``serve`` provides the engine component (``obsw.pluto.obcp.ENGINE``) and runs it from one
loop with the transport: I/O, idle providers, then the procedures that are due. Run it with
``obsw pluto engine [--mission DIR] [--sdb SDB.json]`` or ``python -m obsw_host.obcp``; other
processes load and start procedures through a proxy and subscribe to its events.
``examples/obcp_engine_demo.py`` drives a procedure through the engine and the solar panel.
"""

import argparse
import json
import os
import signal
import sys
import time


def known_interfaces():
    """Interfaces of the host's components: where the engine learns their operations."""
    from obsw_host.solar_panel import SOLAR_PANEL

    return [SOLAR_PANEL]


def load_sdb(path):
    """The spacecraft database at ``path`` for name and type checks: an ``obsw.pus.sdb.Sdb``
    when it loads as one, else the plain JSON document."""
    try:
        from obsw.pus.sdb import load

        return load(path)
    except Exception:  # a database the strict loader refuses still names things
        with open(path) as f:
            return json.load(f)


def serve(directory=None, name="obcp-engine", sdb=None, poll=0.2, out=None, clock=time.time):
    """Provide the OBCP engine in this process until SIGTERM or SIGINT."""
    from obsw.il.node import Node
    from obsw.pluto.engine import provide

    from obsw_host.il.transport import SocketTransport

    node = Node(name)
    transport = SocketTransport(node, directory)
    engine = provide(
        node,
        sdb,
        known_interfaces(),
        timeout=2.0,
        activity_timeout=30.0,
        poll=poll,
    )
    stopping = []

    def stop(signum, frame):
        stopping.append(signum)

    signal.signal(signal.SIGTERM, stop)
    signal.signal(signal.SIGINT, stop)
    if out is not None:
        out("ObcpEngine served by pid %d at %r" % (os.getpid(), transport.address))
    try:
        while not stopping:
            node.poll()
            d = engine.step(clock())
            left = 0.2 if d is None else min(0.2, max(0.0, d - clock()))
            transport.wait(left)
    finally:
        engine.abort_all("engine process stopped")
        engine.system.close()
        transport.close()
    return 0


def _show(out, pub):
    v = pub.value
    m = pub.member
    if m == "step_status":
        out("  step %-8s %s" % (v["step"], v["status"]))
    elif m in ("log", "message", "question"):
        out("  %-13s %s" % ({"message": "user message"}.get(m, m), v["text"]))
    elif m == "finished":
        out("  finished      %s%s" % (v["outcome"], " (%s)" % v["error"] if v["error"] else ""))
    elif m == "failed":
        out("  failed        %s" % v["error"])
    elif m == "raised":
        out("  event raised  %s" % v["event"])
    elif m == "started":
        out("  started       %s" % v["obcp"])


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m obsw_host.obcp", description=__doc__)
    add_arguments(p)
    args = p.parse_args(argv)
    return run_args(args)


def add_arguments(p):
    p.add_argument("--dir", help="name directory (default $OBSW_IL_DIR or a temp dir)")
    p.add_argument("--name", default="obcp-engine", help="node name")
    p.add_argument("--mission", metavar="DIR",
                   help="mission folder whose database names things (default: $OBSW_MISSION, "
                   "else the nearest mission.json)")  # fmt: skip
    p.add_argument("--sdb", help="spacecraft database JSON (overrides the mission's)")
    p.add_argument("--poll", type=float, default=0.2,
                   help="seconds between evaluations of a waited-for condition")  # fmt: skip
    p.add_argument("--quiet", action="store_true")


def run_args(args):
    out = None if args.quiet else (lambda s: print(s, flush=True))
    return serve(args.dir, args.name, load_sdb(args.sdb or _mission_sdb(args.mission)),
                 args.poll, out)  # fmt: skip


def _mission_sdb(mission):
    """The database file of the mission (``locate``: one-line error when there is none)."""
    from obsw_host.mission import config
    from obsw_host.mission.folder import locate

    return config.load(locate(mission)).sdb_path


if __name__ == "__main__":
    sys.exit(main())
