"""PUS demo: an on-board process and a ground process on loopback UDP (port base + APID).

``run(out=print)`` pings the on-board process and prints every packet decoded on the ground
side, one line each; then housekeeping of the solar panel, a parameter set, an event, and
on-board automation: a parameter crossing its limit raises an event (service 12) that fires
an action (service 19), and a time-tagged TC (service 11) runs at its release time.
"""

import sys

from obsw_host.mission.ports import app_port
from obsw_host.sample import SDB_PATH, load_sdb


def _start_onboard(sdb, out, components):
    from obsw_host.pus.onboard import Onboard

    try:
        return Onboard(sdb, components=components).start()
    except OSError as e:  # port base + APID taken (another demo running): any free port
        out("  (port %d busy: %s; using a free port)" % (app_port(sdb.apid("pus")), e.strerror))
        return Onboard(sdb, port=0, components=components).start()


def run(out=print):
    """The demo; returns 0 if every step went as expected."""
    from obsw_host.pus.ground import Ground
    from obsw_host.solar_panel import SOLAR_PANEL, SolarPanel

    sdb = load_sdb(SDB_PATH)
    panel = SolarPanel()
    onboard = _start_onboard(sdb, out, [(SOLAR_PANEL, panel)])
    ok = True
    try:
        host, port = onboard.address[:2]
        out(
            "PUS: on-board application process APID %d on udp %s:%d, ground process on loopback"
            % (onboard.apid, host, port)
        )
        with Ground(sdb, target=(host, port), log=lambda s: out("  " + s)) as ground:
            ok &= _steps(onboard, ground, out)
    finally:
        onboard.stop()
    out("PUS demo %s" % ("done" if ok else "FAILED"))
    return 0 if ok else 1


def _check(out, tx, what):
    out("  => %s: %s" % (what, "ok" if tx.ok else "FAILED " + "; ".join(tx.verification())))
    return tx.ok


def _steps(onboard, ground, out):
    ok = True
    out("1. are-you-alive (service 17)")
    ok &= _check(out, ground.ping(), "alive")

    out("2. one-shot housekeeping report of the solar panel (service 3, structure 1)")
    tx = ground.housekeeping(1)
    ok &= _check(out, tx, "values %s" % (tx.reply or {}).get("values"))

    out("3. set SolarPanel.speed to 7.5 deg/s, then read it back (service 20)")
    ok &= _check(out, ground.set_parameter("SolarPanel.speed", 7.5), "set")
    tx = ground.get_parameters("SolarPanel.speed")
    got = (tx.reply or {}).get("values", {}).get("SolarPanel.speed")
    ok &= _check(out, tx, "read back %s" % got) and got == 7.5

    out("4. setting a read-only parameter is refused at the start of execution")
    tx = ground.set_parameter("SolarPanel.angle", 45.0)
    out("  => %s" % "; ".join(tx.verification()))
    ok &= tx.failure is not None and not tx.ok

    out("5. on board, the panel deploys and turns to 30 deg: events (service 5) and HK")
    mark = len(ground.received)

    def act():
        onboard.node.start("SolarPanel.deploy", timeout=1.0)
        onboard.node.poll()
        onboard.node.call("SolarPanel.set_angle", (30.0,), timeout=1.0)

    onboard.call(act)
    got = ground.wait_for(5, 1, timeout=2.0, since=mark)
    ok &= got is not None
    out("  => event %s" % (got[1] if got else "MISSING"))
    hk = None
    while hk is None:  # periodic reports until one shows the new angle (or none comes)
        r = ground.wait_for(3, 25, timeout=2.5, since=mark)
        if r is None:
            break
        mark = len(ground.received)
        if r[1].get("values", {}).get("SolarPanel.angle") == 30.0:
            hk = r
    ok &= hk is not None
    out("  => periodic HK shows angle %s" % (hk[1]["values"] if hk else "MISSING"))

    out("6. time report every second (service 9)")
    mark = len(ground.received)
    ok &= _check(out, ground.set_time_rate(0), "rate set")
    got = ground.wait_for(9, 2, timeout=2.5, since=mark)
    ok &= got is not None
    if got:
        from obsw.utc import format_utc

        out("  => on-board time %s" % format_utc(got[1]["time"]))
    ok &= _automation(ground, out)
    return bool(ok)


def _automation(ground, out):
    ok = True
    out("7. automation: monitoring (12) -> event (5) -> event-action (19); time-tagged TC (11)")
    tx = ground.add_limit_monitor(
        1,
        "SolarPanel.speed",
        0.5,
        10.0,
        low_event="monitoring.speed_low",
        high_event="monitoring.speed_high",
    )
    ok &= _check(out, tx, "PMON 1 checks SolarPanel.speed within [0.5, 10] deg/s")
    action = ground.parameter_request({"SolarPanel.speed": 5.0})
    tx = ground.add_action("monitoring.speed_high", action)
    ok &= _check(out, tx, "on monitoring.speed_high, set SolarPanel.speed to 5 deg/s")
    timed = ground.function_request("SolarPanel.set_angle", angle=15.0)
    ok &= _check(out, ground.schedule_in(1.0, timed), "SolarPanel.set_angle(15) in 1 s")
    mark = len(ground.received)
    ok &= _check(out, ground.set_parameter("SolarPanel.speed", 12.0), "speed set to 12 deg/s")
    got = ground.wait_for(5, 3, timeout=2.0, since=mark)
    ok &= got is not None
    out("  => event %s" % (got[1] if got else "MISSING"))
    ground.wait(action, 2.0, raise_on_timeout=False)
    ok &= _check(out, action, "event-action TC[20,3] ran on board")
    ground.wait(timed, 3.0, raise_on_timeout=False)
    ok &= _check(out, timed, "time-tagged TC[8,1] ran at its release time")
    tx = ground.get_parameters("SolarPanel.speed", "SolarPanel.angle")
    values = (tx.reply or {}).get("values", {})
    ok &= _check(out, tx, "now %s" % values)
    ok &= values.get("SolarPanel.speed") == 5.0 and values.get("SolarPanel.angle") == 15.0
    return ok


if __name__ == "__main__":
    sys.exit(run())
