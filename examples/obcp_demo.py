"""OBCP demo: the ground uploads a PLUTO procedure with PUS service 18 and starts it.

``run(out=print)`` builds the on-board PUS application process (``Onboard``) with the solar
panel component, the OBCP engine on the same interaction layer node and the service 18
provider over it, and a ground process on loopback UDP. The ground uploads the procedure
(TC[18,1]), lists the OBCPs (TC[18,8] / TM[18,9]), activates it (TC[18,3]); the procedure
reads ``angle of SolarPanel``, deploys the panel and turns it with ``initiate and confirm
set_angle of SolarPanel``, and its progress arrives as service 5 events decoded on the ground.
A procedure with a syntax error is refused with its line and column; a procedure file of the
on-board filestore is loaded by reference (TC[18,13]). A few seconds; everything is stopped
and removed at the end.

The on-board part on its own is ``obsw_host.pus.obcp_onboard`` (``obsw obcp serve``).
"""

import os
import shutil
import sys
import tempfile
import time

BROKEN = """procedure
  main
    log "no semicolon after this line"
  end main
end procedure
"""


def run(out=print, timeout=15.0):
    """The demo; returns 0 if every step went as expected."""
    from obcp_engine_demo import DEMO_PROCEDURE
    from obsw_host.pus.ground import Ground
    from obsw_host.pus.obcp_ground import ObcpGround, explain
    from obsw_host.pus.obcp_onboard import onboard_with_obcp
    from obsw_host.sample import SDB_PATH, load_sdb

    sdb = load_sdb(SDB_PATH)
    files = tempfile.mkdtemp(prefix="obsw-obcp-files-")
    os.mkdir(os.path.join(files, "obcp"))
    with open(os.path.join(files, "obcp", "turn_panel.plt"), "w") as f:
        f.write(DEMO_PROCEDURE)
    onboard, engine = onboard_with_obcp(sdb, files=files, port=0)
    ok = True
    try:
        onboard.start()
        host, port = onboard.address[:2]
        out(
            "OBCP: PUS service 18 on the on-board process APID %d (udp %s:%d), the OBCP engine"
            " and the solar panel on its interaction layer; ground on loopback"
            % (onboard.apid, host, port)
        )
        with Ground(sdb, target=(host, port), timeout=5.0) as ground:
            ok = _steps(ObcpGround(ground), out, explain, DEMO_PROCEDURE, timeout)
    finally:
        onboard.call(lambda: engine.abort_all("demo ended"))
        onboard.stop()
        engine.system.close()
        shutil.rmtree(files, ignore_errors=True)
    out("OBCP demo %s" % ("done" if ok else "FAILED"))
    return 0 if ok else 1


def _check(out, tx, what, explain):
    out("  => %s: %s" % (what, "; ".join(explain(tx))))
    return tx.ok


def _show_status(out, status):
    for name, o in status.items():
        out(
            "     %-11s %-9s last outcome %-13s activations %d, %d statements, line %d%s"
            % (
                name,
                o["status"],
                o["outcome"],
                o["activations"],
                o["statements"],
                o["line"],
                ", in step " + o["step"] if o["step"] else "",
            )
        )


def _show_event(out, name, data):
    obcp = data.get("obcp", "")
    if name == "step_status":
        text = "step %s %s" % (data["step"], data["status"])
    elif name == "finished":
        text = "finished %s%s" % (
            data["outcome"],
            " (%s)" % data["error"] if data["error"] else "",
        )
    elif name in ("log", "message", "question"):
        text = "%s: %s" % ({"message": "user message"}.get(name, name), data["text"])
    elif name == "state_changed":
        text = "state %s" % data["state"]
    elif name == "failed":
        text = "failed: %s" % data["error"]
    elif name == "raised":
        text = "raised event %s" % data["event"]
    else:
        text = name
    out("     event %-10s %s" % (obcp, text))


def _steps(obcp, out, explain, procedure, timeout):
    ok = True
    out("1. upload the procedure turn_panel (TC[18,1], %d lines of PLUTO)" % procedure.count("\n"))
    ok &= _check(out, obcp.load("turn_panel", procedure), "loaded", explain)

    out("2. a procedure with a syntax error is refused (start failure with line and column)")
    tx = obcp.load("broken", BROKEN)
    _check(out, tx, "refused", explain)
    ok &= tx.failure is not None

    out("3. status of each OBCP (TC[18,8] -> TM[18,9])")
    status = obcp.status()
    _show_status(out, status)
    ok &= list(status) == ["turn_panel"]

    out("4. activate turn_panel, observability 'statement' (TC[18,3]); progress as events")
    obcp.events()  # what came before is not this run's
    ok &= _check(out, obcp.activate("turn_panel", level=3), "activated", explain)
    outcome = None
    deadline = time.monotonic() + timeout
    while outcome is None and time.monotonic() < deadline:
        for name, data in obcp.events(timeout=0.5):
            _show_event(out, name, data)
            if name == "finished" and data.get("obcp") == "turn_panel":
                outcome = data["outcome"]
    ok &= outcome == "confirmed"

    out("5. status after the run")
    status = obcp.status()
    _show_status(out, status)
    ok &= status["turn_panel"]["outcome"] == "confirmed"

    out("6. load a procedure file of the on-board filestore by reference (TC[18,13])")
    tx = obcp.load_by_reference("from_file", "obcp", "turn_panel.plt")
    ok &= _check(out, tx, "loaded", explain)
    out("7. unload both (TC[18,2])")
    for name in ("turn_panel", "from_file"):
        ok &= _check(out, obcp.unload(name), "unloaded " + name, explain)
    ok &= obcp.status() == {}
    return bool(ok)


if __name__ == "__main__":
    sys.exit(run())
