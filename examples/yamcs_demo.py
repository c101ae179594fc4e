"""Demo: Yamcs, with the mission database generated from the spacecraft database, operates the
sample spacecraft over the packet link: housekeeping, commands verified by service 1, events,
an alarm and a CFDP upload. Skipped, saying why, when Java or Yamcs is not installed."""

import logging
import os
import socket
import tempfile

from obsw_host.sample import SDB_PATH

MISSION = "/obsw-demo"


def _free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def run(out=print):
    from obsw_host.yamcs import database, server
    from obsw_host.yamcs.instance import write_instance
    from obsw_host.yamcs.spacecraft import SampleSpacecraft

    problem = server.missing()
    if problem is None:
        try:
            from yamcs.client import YamcsClient
        except ImportError:
            problem = "the Yamcs client is not installed: pip install yamcs-client"
    if problem:
        out("skipped: " + problem)
        return 0
    with tempfile.TemporaryDirectory() as folder:
        sat = SampleSpacecraft(SDB_PATH, os.path.join(folder, "sat"))
        http_port = _free_port()
        try:
            write_instance(folder, database.load(SDB_PATH), "packets", sat.ports(), http_port)
            sat.start()
            yamcs = server.Yamcs(folder, http_port).start(timeout=120)
            # the client logs each subscription Yamcs closes on shutdown as an error
            quiet = [logging.getLogger(n) for n in ("yamcs-client", "websocket")]
            levels = [q.level for q in quiet]
            try:
                _operate(out, YamcsClient("127.0.0.1:%d" % http_port), sat, folder)
                for q in quiet:
                    q.setLevel(logging.CRITICAL)
            finally:
                yamcs.stop()
                for q, level in zip(quiet, levels):
                    q.setLevel(level)
        finally:
            sat.close()
    return 0


def _operate(out, client, sat, folder):
    out("Yamcs %s runs instance 'obsw' with the generated XTCE; packet link to the OBC" % "5.12.8")
    proc = client.get_processor("obsw", "realtime")
    for name in ("angle", "speed", "is_deployed"):
        pv = proc.get_parameter_value(MISSION + "/SolarPanel/" + name, from_cache=False)
        out(
            "  HK  %-34s = %-6s (on board: %s)" % (pv.name, pv.eng_value, getattr(sat.panel, name))
        )
    conn = proc.create_command_connection()
    events = []
    client.create_event_subscription("obsw", on_data=events.append)
    for command, args in (
        ("/PUS/ping", None),
        ("/SolarPanel/set_speed", {"value": 12.0}),
        ("/SolarPanel/deploy", None),
        ("/SolarPanel/set_angle", {"angle": 30.0}),
        ("/SolarPanel/set_angle", {"angle": 1000.0}),
    ):
        cmd = conn.issue(MISSION + command, args=args)
        cmd.await_complete(timeout=30)
        acks = cmd.acknowledgments
        stages = " ".join(
            "%s %s" % (k.split("_")[1].lower(), acks[k].status)
            for k in ("Verifier_Accepted", "Verifier_Started", "Verifier_Complete")
            if k in acks
        )
        result = "completed" if cmd.is_success() else "failed: %s" % cmd.error
        if cmd.is_success() == (command == "/SolarPanel/set_angle" and args["angle"] > 90):
            raise RuntimeError("%s: unexpected outcome %s" % (command, result))
        out("  TC  %-34s %s -> %s" % (command + (" %s" % args if args else ""), stages, result))
    pv = proc.get_parameter_value(MISSION + "/SolarPanel/speed", from_cache=False)
    out(
        "  HK  speed %s deg/s: monitoring %s (database warning range 1..10)"
        % (pv.eng_value, pv.monitoring_result)
    )
    for e in events:
        if e.message and e.message.startswith("SolarPanel"):
            out("  EV  %-8s %s" % (e.severity, e.message))
    path = os.path.join(folder, "files", "obsw", "up", "patch.bin")
    with open(path, "wb") as f:
        f.write(os.urandom(20000))
    service = client.get_file_transfer_client("obsw").get_service("cfdp0")
    tx = service.upload("obsw_up", "patch.bin", "patch.bin", options={"reliable": True})
    tx.await_complete(timeout=60)
    sat.wait_finished(role="R", timeout=30)
    with open(path, "rb") as a, open(os.path.join(sat.root, "patch.bin"), "rb") as b:
        same = a.read() == b.read()
    out(
        "  CFDP class 2 upload of 20000 bytes: %s, on board %s"
        % (tx.state, "byte-identical" if same else "DIFFERENT")
    )
    if not same:
        raise RuntimeError("the file Yamcs sent differs from what the OBC received")
    proc.issue_command(MISSION + "/SolarPanel/set_speed", args={"value": 5.0})
