"""The OBCP engine in its own process on the interaction layer's socket transport, and its demo.

``serve`` provides the engine component (``obsw.pluto.obcp.ENGINE``) and runs it from one
loop with the transport: I/O, idle providers, then the procedures that are due. Run it with
``obsw pluto engine [--dir DIR] [--sdb SDB.json]`` or ``python -m obsw_host.obcp``; other
processes load and start procedures through a proxy and subscribe to its events.
``demo(out=print)`` starts the solar panel and the engine as two processes and drives a
procedure through them.
"""

import argparse
import json
import os
import signal
import sys
import tempfile
import time

DEFAULT_SDB = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "sdb.json")

DEMO_PROCEDURE = """\
// Deploy the solar panel, then turn it to 30 degrees and wait until it is there.
procedure
  main
    initiate and confirm step Deploy
      main
        log "angle before: ", angle of SolarPanel;
        initiate and confirm deploy of SolarPanel;
      end main
    end step;
    initiate and confirm step Turn
      main
        initiate and confirm set_angle of SolarPanel with arguments angle := 30 deg end with;
        wait until angle of SolarPanel > 29.5 deg timeout 5 s;
        log "angle after: ", angle of SolarPanel;
      end main
    end step;
    inform user "solar panel deployed and at 30 deg";
  end main
end procedure
"""


def known_interfaces():
    """Interfaces of the host's components: where the engine learns their operations."""
    from obsw_host.solar_panel import SOLAR_PANEL

    return [SOLAR_PANEL]


def load_sdb(path=None):
    """The spacecraft database for name and type checks: ``path``, else the packaged one;
    an ``obsw.pus.sdb.Sdb`` when it loads as one, else the plain JSON document."""
    path = path or DEFAULT_SDB
    if not os.path.exists(path):
        return None
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
        sdb if sdb is not None else load_sdb(),
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


def demo(out=print, directory=None):
    """The solar panel and the OBCP engine in their own processes; a procedure loaded and
    activated through a proxy reads the panel's angle, deploys it, turns it with
    ``set_angle`` and waits for the angle; its progress prints as the events arrive."""
    from obsw.il.node import Node
    from obsw.pluto.obcp import ENGINE

    from obsw_host.il.transport import SocketTransport
    from obsw_host.il_demo import _remove_tree, spawn, stop
    from obsw_host.solar_panel import SOLAR_PANEL

    own_dir = directory is None
    directory = directory or tempfile.mkdtemp(prefix="obsw-obcp-demo-")
    out("OBCP engine: a PLUTO procedure drives the solar panel, each in its own process")
    procs = [spawn("obsw_host.solar_panel", directory), spawn("obsw_host.obcp", directory)]
    node = Node("demo-operator")
    transport = SocketTransport(node, directory, listen=False)
    try:
        engine = node.proxy(ENGINE, timeout=10.0, retries=1)
        events = engine.subscribe("*", length=64)
        engine.load("turn_panel", DEMO_PROCEDURE)
        out("  loaded        turn_panel (%d lines); OBCPs: %s"
            % (DEMO_PROCEDURE.count("\n"), ", ".join(engine.obcps)))  # fmt: skip
        engine.activate("turn_panel", None)
        deadline = time.monotonic() + 20.0
        outcome = None
        while outcome is None and time.monotonic() < deadline:
            pub = events.receive(timeout=0.5)
            if not pub or pub.member in ("obcps", "states", "state_changed"):
                continue
            _show(out, pub)
            if pub.member == "finished" and pub.value["obcp"] == "turn_panel":
                outcome = pub.value["outcome"]
        status = engine.status("turn_panel")
        out("  status        %s, %s after %d statements"
            % (status["state"], status["outcome"], status["statements"]))  # fmt: skip
        panel = node.proxy(SOLAR_PANEL, timeout=10.0)
        out("  SolarPanel    angle %.1f deg, deployed %s" % (panel.angle, panel.is_deployed))
        engine.unload("turn_panel")
        out("  unloaded      OBCPs: %s" % (engine.obcps or "none"))
    finally:
        transport.close()
        for p in reversed(procs):
            stop(p)
        out("  engine and panel processes stopped")
        if own_dir:
            _remove_tree(directory)
    return 0 if outcome == "confirmed" else 1


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m obsw_host.obcp", description=__doc__)
    add_arguments(p)
    args = p.parse_args(argv)
    return run_args(args)


def add_arguments(p):
    p.add_argument("--dir", help="name directory (default $OBSW_IL_DIR or a temp dir)")
    p.add_argument("--name", default="obcp-engine", help="node name")
    p.add_argument("--sdb", help="spacecraft database JSON (default: the packaged one)")
    p.add_argument("--poll", type=float, default=0.2,
                   help="seconds between evaluations of a waited-for condition")  # fmt: skip
    p.add_argument("--quiet", action="store_true")


def run_args(args):
    out = None if args.quiet else (lambda s: print(s, flush=True))
    return serve(args.dir, args.name, load_sdb(args.sdb), args.poll, out)


if __name__ == "__main__":
    sys.exit(main())
