"""Example: the OBCP engine and the solar panel in their own processes, used through a proxy."""

import sys
import tempfile
import time

from obsw_host.obcp import _show

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


def demo(out=print, directory=None):
    """The solar panel and the OBCP engine in their own processes; a procedure loaded and
    activated through a proxy reads the panel's angle, deploys it, turns it with
    ``set_angle`` and waits for the angle; its progress prints as the events arrive."""
    from obsw.il.node import Node
    from obsw.pluto.obcp import ENGINE
    from obsw_host.il.processes import remove_tree, spawn, stop
    from obsw_host.il.transport import SocketTransport
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
            remove_tree(directory)
    return 0 if outcome == "confirmed" else 1


if __name__ == "__main__":
    sys.exit(demo())
