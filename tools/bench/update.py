"""Benchmark of in-flight updates on a running OBC (`obsw obc serve` of a copy of the sample):
the size of a full package and of a one-module delta, the upload of the full one by CFDP class
2 over UDP (the sample link), and the time from activation to a confirmed version and to the
rollback of a version that crashes at start, next to the goal: the trial's deadline.

update.py [--quick] [--json]
"""

import json
import os
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path[:0] = [os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]

from obsw_host.update import build as b  # noqa: E402
from obsw_sim.update_rig import CRASH, DEADLINE, HEALTHY_AFTER, UpdateRig, wait  # noqa: E402


def measure(quick):
    with tempfile.TemporaryDirectory(prefix="obsw-bench-update-") as work:
        rig = UpdateRig(work)
        full, manifest, build_s = rig.package("1.1")
        base = b.base_manifest(full, rig.public, rig.ids.config.name, "obc")
        delta, _, _ = rig.package("1.2", {"lib/obsw_host/update_note.py": "NOTE = 1\n"}, base)
        broken, _, _ = rig.package("1.3", CRASH, base)
        rig.start()
        try:
            upload_s = rig.upload(full)
            seq = rig.record().get("seq", 0)
            t0 = rig.stage_and_activate(full)
            confirm_s = rig.until("confirmed", DEADLINE + 60) - t0
            if not any(e["seq"] > seq and e["event"] == "confirmed" for e in rig.record()["log"]):
                raise RuntimeError("1.1 was not confirmed")
            rollback_s = None
            if not quick:
                wait(rig._answers, 30)
                rig.upload(broken)
                t0 = rig.stage_and_activate(broken)
                rollback_s = rig.until("rolled_back", DEADLINE + 60) - t0
        finally:
            rig.stop()
        return {
            "full_bytes": os.path.getsize(full),
            "files": len(manifest["tree"]),
            "delta_bytes": os.path.getsize(delta),
            "build_s": build_s,
            "upload_s": upload_s,
            "confirm_s": confirm_s,
            "rollback_s": rollback_s,
        }


def main(argv):
    quick = "--quick" in argv
    m = measure(quick)
    rows = [
        ("package size: a one-module delta vs the full one (%d files)" % m["files"],
         m["delta_bytes"], m["full_bytes"], "B"),
        ("upload of the full package, CFDP class 2 over UDP", m["upload_s"], DEADLINE, "s"),
        ("activation to confirmed (healthy_after %.0f s)" % HEALTHY_AFTER, m["confirm_s"],
         DEADLINE, "s"),
    ]  # fmt: skip
    if m["rollback_s"] is not None:
        rows.append(("activation to rollback of a version that crashes at start",
                     m["rollback_s"], DEADLINE, "s"))  # fmt: skip
    if "--json" in argv:
        out = []
        for case, ours, ref, unit in rows:
            for impl, value in (("obsw", ours), ("reference", ref)):
                out.append({"case": case, "impl": impl, "value": value, "unit": unit,
                            "higher_is_better": False})  # fmt: skip
        print(json.dumps({"bench": "update", "rows": out}))
        return 0
    print("%-62s %12s %12s %7s" % ("case", "obsw", "reference", "ratio"))
    for case, ours, ref, unit in rows:
        print("%-62s %11.4g%s %11.4g%s %7.3f" % (case, ours, unit, ref, unit, ours / ref))
    print("reference: the full package for its size, else the trial's deadline (%g s); "
          "upload %.1f MB/s; package built in %.2f s" % (
              DEADLINE, m["full_bytes"] / m["upload_s"] / 1e6, m["build_s"]))  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
