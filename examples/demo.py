"""The demo: the system's capabilities, simulated on one machine, one section after another."""

import importlib
import sys
import time

# (title, module, function): each function takes `out` (a print-like callable), runs its part of
# the system on this machine, prints what happens and cleans up after itself.
SECTIONS = (
    ("PUS monitoring & control: ground and onboard over UDP", "pus_demo", "run"),
    ("Interaction layer: a component in its own process", "il_demo", "run"),
    ("SpaceCAN: OBC master and equipment, a node on two buses", "spacecan_demo", "run"),
    ("Space data link: CLTUs and TM frames on two UARTs", "frames_demo", "run"),
    ("CFDP: class 2 file delivery over a lossy link, and a get", "cfdp_demo", "run"),
    ("Storage and files: store, pass, CFDP copies", "storage_demo", "run"),
    ("OBCPs: ground uploads a PLUTO procedure with service 18", "obcp_demo", "run"),
    ("Reconfiguration module: two MicroPython controllers", "obsw_sim.reconfig_scenario", "demo"),
    ("Firmware: the reconfiguration image on a QEMU Cortex-M board", "obsw_host.board", "demo"),
    ("The whole OBC: the 12-step chain and its faults", "obsw_sim.chain", "demo"),
    (
        "In-flight update: a new version confirmed, a broken one rolled back",
        "obsw_sim.update_rig",
        "demo",
    ),
    ("Mission control: Yamcs operates the sample spacecraft", "yamcs_demo", "run"),
    (
        "Space link: concatenated coding at 9,600 bit/s, BER 1e-3, into Yamcs",
        "spacelink_demo",
        "run",
    ),
    (
        "Operations across passes: orbit, store-and-forward, files across passes",
        "passes_demo",
        "run",
    ),
)


def _interrupt(signum, frame):
    raise KeyboardInterrupt  # so every section's cleanup (finally blocks) runs on SIGTERM too


def main(out=print):
    import signal

    signal.signal(signal.SIGTERM, _interrupt)
    failed = []
    started = time.monotonic()
    for n, (title, module, function) in enumerate(SECTIONS, 1):
        out("")
        out("=" * 78)
        out("%d. %s" % (n, title))
        out("=" * 78)
        try:
            getattr(importlib.import_module(module), function)(out=out)
        except Exception as e:  # one broken section must not hide the others
            failed.append(title)
            out("!! section failed: %s: %s" % (type(e).__name__, e))
    out("")
    out(
        "demo finished in %.1f s: %d sections, %d failed"
        % (time.monotonic() - started, len(SECTIONS), len(failed))
    )
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
