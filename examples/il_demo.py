"""Demo of the interaction layer: the solar panel in its own process, used through a proxy.

``run(out=print)`` starts the panel process, reads and sets attributes, calls operations,
receives events and status updates, shows a typed error crossing the process boundary, kills
the provider and sees the user recover once it is restarted, then stops it cleanly.
"""

import signal
import sys
import tempfile

from obsw_host.il.processes import python_path, remove_tree, spawn, stop  # noqa: F401


def run(out=print, directory=None):
    from obsw.il.errors import ComponentError
    from obsw.il.node import Node
    from obsw_host.il.transport import SocketTransport
    from obsw_host.solar_panel import SOLAR_PANEL

    own_dir = directory is None
    directory = directory or tempfile.mkdtemp(prefix="obsw-il-demo-")
    out("interaction layer: SolarPanel in its own process, used through a proxy")
    panel_proc = spawn("obsw_host.solar_panel", directory)
    node = Node("demo-user")
    transport = SocketTransport(node, directory, listen=False)
    try:
        panel = node.proxy(SOLAR_PANEL, timeout=10.0, retries=1)
        out(
            "  provider process started, pid %d; names resolve via %s"
            % (panel_proc.pid, directory)
        )
        out("  get angle          -> %.1f deg" % panel.get("angle"))
        out("  get speed          -> %.1f deg/s" % panel.speed)
        try:
            panel.set_angle(30)
        except ComponentError as e:
            out("  set_angle(30)      -> ComponentError %s: %s" % (e.code, e.message))
        events = panel.subscribe("*", length=16)
        updates = []
        pending = panel.deploy(on_status=lambda p, state, value: updates.append(value))
        result = pending.result(timeout=10.0)
        for u in updates:
            if isinstance(u, dict):
                out("  deploy status      -> hinge %d of %d released" % (u["hinge"], u["of"]))
        out("  deploy             -> %s" % result)
        out("  set_angle(30)      -> %.1f deg" % panel.set_angle(30))
        panel.set("speed", 2.5)
        out("  set speed 2.5      -> %.1f deg/s" % panel.get("speed"))
        try:
            panel.set_angle(120)
        except ComponentError as e:
            out("  set_angle(120)     -> ComponentError %s, data %s" % (e.code, e.data))
        while True:
            pub = events.receive(timeout=0.2)
            if not pub:
                break
            out("  publication        <- %s = %s" % (pub.name, pub.value))
        panel_proc.send_signal(signal.SIGKILL)
        panel_proc.wait(10)
        out("  provider killed (SIGKILL); restarting it")
        panel_proc = spawn("obsw_host.solar_panel", directory)
        out(
            "  restarted, pid %d; get angle -> %.1f deg (a fresh panel)"
            % (
                panel_proc.pid,
                panel.get("angle"),
            )
        )
        out(
            "  calls retried: %d; deploy again -> %s"
            % (
                node.retries,
                panel.deploy().result(timeout=10.0),
            )
        )
        out("  set_angle(-15)     -> %.1f deg" % panel.set_angle(-15))
        pub = events.receive(timeout=5.0)
        while pub and pub.member != "angle_reached":
            pub = events.receive(timeout=5.0)
        out("  event after restart <- %s" % (pub.value if pub else "none"))
    finally:
        transport.close()
        status = stop(panel_proc)
        out("  provider stopped cleanly (exit status %d)" % status)
        if own_dir:
            remove_tree(directory)
    return 0


if __name__ == "__main__":
    sys.exit(run())
