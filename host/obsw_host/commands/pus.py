"""`obsw pus`: the PUS-C standard against what the OBC serves.

`obsw pus coverage [CONFIG]` lists every message type of ECSS-E-ST-70-41C services 1-23, by
service, and whether the OBC of mission CONFIG (a mission folder or its file; default:
$OBSW_MISSION, or a mission.json here or above) serves it, from the service tables its PUS
application process registers. `--missing` lists only the types not served; `--json` prints
the whole report for scripts.
"""

import json

from obsw_host.pus.coverage import coverage, obc_services


def add_parser(sub):
    p = sub.add_parser("pus", help="PUS-C: the standard's message types the OBC serves",
                       description=__doc__)  # fmt: skip
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True
    c = s.add_parser("coverage", help="every standard message type and whether the OBC serves it")
    c.add_argument(
        "config",
        nargs="?",
        help="mission folder or file (default: $OBSW_MISSION, or a mission.json here or above)",
    )
    c.add_argument("--missing", action="store_true", help="list only the types not served")
    c.set_defaults(func=coverage_cmd)


def coverage_cmd(args):
    report = coverage(obc_services(args.config))
    if args.json:
        print(json.dumps(report, indent=1))
        return 0
    for s in report["services"]:
        print("ST[%02d] %-32s %3d of %3d" % (s["service"], s["name"], s["served"], s["total"]))
        for t in s["types"]:
            if args.missing and t["served"]:
                continue
            mark = "served" if t["served"] else "MISSING"
            print("  %-10s %-7s %s" % (t["type"], mark, t["title"]))
    print("%d of %d message types served" % (report["served"], report["total"]))
    return 0
