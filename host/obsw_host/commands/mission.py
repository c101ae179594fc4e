"""`obsw mission check|new|upgrade`: the mission folder a team writes, checked before a start.

`check [DIR]` checks the whole folder (the mission file and the database against their JSON
Schemas, then names, ids and references between the files, node definitions, procedures and
components) and prints one line per problem: `FILE: $.json.path: what is wrong; expected ...`
(exit status 2). `new NAME [--dir D]` writes a mission folder that passes the check and runs
under `obsw obc serve`. `upgrade FILE` converts an older mission file to the current format.
"""

import json
import sys

from obsw_host import mission
from obsw_host.errors import UserError, read_json


def add_parser(sub):
    p = sub.add_parser("mission", help="check, create or upgrade a mission folder",
                       description=__doc__)  # fmt: skip
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True
    c = s.add_parser("check", help="check the whole mission folder; one line per problem")
    c.add_argument("dir", nargs="?", help="mission folder or file (default: $OBSW_MISSION, or "
                   "a mission.json here or above)")  # fmt: skip
    c.set_defaults(func=check_cmd)
    n = s.add_parser("new", help="write a new mission folder from the shipped template")
    n.add_argument("name", help="the spacecraft's name (letters, digits, '_', '.', '-')")
    n.add_argument("--dir", help="the folder to write (default: ./NAME; with --count, the "
                   "folder of the missions, default: .)")  # fmt: skip
    n.add_argument("--from", dest="template", metavar="DIR",
                   help="copy this mission folder instead of the shipped template")  # fmt: skip
    n.add_argument("--scid", type=int, help="the spacecraft id (with --count, the first one's; "
                   "default: the template's, + 1 per mission)")  # fmt: skip
    n.add_argument("--port-base", type=int, help="the mission's port base (with --count, the "
                   "first one's, default 20000; each next one 200 above)")  # fmt: skip
    n.add_argument("--slot", type=int, help="the ids' slot, 0 to 199: APIDs 400 + 8 x SLOT "
                   "(pus; frames + 2, cfdp + 4), spacecraft id 500 + SLOT, CFDP entities "
                   "20 + 2 x SLOT and the next (default: from the name)")  # fmt: skip
    n.add_argument("--count", type=int, help="write N missions NAME-1 .. NAME-N, each with "
                   "its own spacecraft id and ports (a fleet for one Yamcs)")  # fmt: skip
    n.set_defaults(func=new_cmd)
    u = s.add_parser("upgrade", help="convert a format-1 mission file to format 2")
    u.add_argument("file", help="the mission file (rewritten in place unless --output)")
    u.add_argument("-o", "--output", help="write the upgraded file here instead")
    u.set_defaults(func=upgrade_cmd)


def check_cmd(args):
    from obsw_host.mission.check import check

    path = mission.locate(args.dir)
    m, problems = check(path)
    if args.json:
        print(json.dumps({"mission": path, "ok": not problems,
                          "problems": [str(p) for p in problems]}, indent=2))  # fmt: skip
    else:
        for p in problems:
            print(p, file=sys.stderr)
    if problems:
        return 2
    if not args.json:
        sdb = m.sdb
        print("%s: ok (%s; %d parameters, %d events, %d functions, components %s)" % (
            path, m.name, len(sdb.parameters), len(sdb.events), len(sdb.functions),
            ", ".join(sorted(m.interfaces)) or "none"))  # fmt: skip
    return 0


def new_cmd(args):
    from obsw_host.mission import new

    if args.count is not None:
        base = new.FLEET_BASE if args.port_base is None else args.port_base
        template = args.template or new.TEMPLATE_DIR
        folders = new.fleet(template, args.name, args.dir or ".", args.count, args.scid, base)
        for folder in folders:
            ids = _ids(folder)  # the mission file's base ($OBSW_PORT_BASE moves a run, not it)
            print("%s: mission %s, spacecraft id %s, port base %d"
                  % (folder, ids.name, ids.scid, ids.config.doc["ports"]["base"]))  # fmt: skip
        return 0
    if args.template:
        folder = new.copy(args.template, args.name, args.dir or args.name, args.scid,
                          args.port_base)  # fmt: skip
    else:
        folder, _ = new.write(args.name, args.dir or args.name, args.slot)
        if args.scid is not None or args.port_base is not None:
            new.retarget_folder(folder, args.scid, args.port_base)
    ids = _ids(folder)
    local, ground = ids.cfdp_entities
    print("%s: mission %s written: APIDs %s, spacecraft id %s, CFDP entities %d (onboard) and "
          "%d (ground), PUS port %d; next: obsw mission check %s && obsw obc serve %s"
          % (folder, args.name, ", ".join("%s %d" % kv for kv in ids.sdb.apids.items()),
             ids.sdb.scid, local, ground, ids.ports.pus, folder, folder))  # fmt: skip
    return 0


def _ids(folder):
    from obsw_host.mission.ids import MissionIds

    return MissionIds.locate(folder)


def upgrade_cmd(args):
    from obsw_host.mission.upgrade import upgrade

    doc = read_json(args.file, "mission file")
    if not isinstance(doc, dict):
        raise UserError("%s is not a JSON object" % args.file, expected="a mission file")
    if "format" not in doc and "processes" not in doc:  # a database, a node: left as it is
        raise UserError("%s is not a mission file (no format, no processes)" % args.file,
                        expected="a format-1 mission file; nothing was changed")  # fmt: skip
    new, changes = upgrade(doc)
    if not changes:
        print("%s: already format %d" % (args.file, new["format"]))
        return 0
    out = args.output or args.file
    with open(out, "w", encoding="utf-8") as f:
        json.dump(new, f, indent=2)
        f.write("\n")
    print("%s: %s" % (out, "; ".join(changes)))
    return 0
