"""`obsw pluto`: check a PLUTO procedure at load time, or dry-run it against a simulated system."""

import json
import sys

from obsw.pluto.dryrun import dry_run
from obsw.pluto.interp import load
from obsw.pluto.lexer import PlutoError
from obsw.pluto.parser import parse
from obsw.pluto.system import SimulatedSystem, SystemSpecError, argument_code, value_of
from obsw.pluto.units import Quantity

from obsw_host.errors import UserError, read_json

_TYPES = {"real": "r", "float": "r", "double": "r", "bool": "b", "boolean": "b", "str": "s",
          "string": "s", "int": "i", "integer": "i", "uint": "u", "unsigned": "u"}  # fmt: skip


def add_parser(sub):
    p = sub.add_parser("pluto", help="check or dry-run PLUTO procedures", description=__doc__)
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True
    c = s.add_parser("check", help="load-time check (syntax, references, types)")
    c.add_argument("file", help="procedure text")
    c.add_argument("--sdb", help="spacecraft database JSON: check system references")
    c.add_argument("--system", help="simulated system JSON: check system references")
    c.add_argument(
        "--mission",
        metavar="DIR",
        help="mission folder: check references against its database and components",
    )
    c.add_argument(
        "--syntax-only",
        action="store_true",
        help="the grammar only (ECSS-E-ST-70-32C Annex A): no references, no types",
    )
    c.set_defaults(func=check_cmd)
    r = s.add_parser("run", help="run against a simulated system on a virtual clock")
    r.add_argument("file", help="procedure text")
    r.add_argument("--system", help="simulated system JSON (parameters, activities, events)")
    r.add_argument("--arg", action="append", default=[], metavar="NAME=VALUE",
                   help="procedure argument (value as JSON, else text)")  # fmt: skip
    r.add_argument("-q", "--quiet", action="store_true", help="do not print each statement")
    r.set_defaults(func=run_cmd)
    e = s.add_parser("engine", help="serve the OBCP engine component in this process")
    from obsw_host.obcp import add_arguments

    add_arguments(e)
    e.set_defaults(func=engine_cmd)


def _type_code(t):
    # SDB types: uint8..uint64, int8..int64, float32/64, bool, string, enum8/16, or names
    t = str(t or "").lower()
    for prefix, code in (("float", "r"), ("uint", "i"), ("int", "i"), ("bool", "b")):
        if t.startswith(prefix):
            return code
    return _TYPES.get(t, "?")


class SdbResolver:
    """Answers the checker's questions from the spacecraft database (an ``obsw.pus.sdb.Sdb``
    or its JSON document, parsed by that one parser): component parameters, operations and
    events."""

    def __init__(self, sdb):
        from obsw.pus.sdb import Sdb

        if isinstance(sdb, dict):
            sdb = Sdb(sdb)
        self.known = {}
        for p in sdb.parameters.values():
            if p.component:
                code = _type_code(p.type_spec)
                self.known["%s of %s" % (p.name, p.component)] = ("parameter", code, p.unit)
        self.signatures = {}
        for op in sdb.operations.values():
            path = "%s of %s" % (op.name, op.component)
            self.known[path] = ("activity", "?", None)
            if op.signature is not None:
                self.signatures[path] = [(n, argument_code(t), u) for n, t, u in op.signature]
        for e in sdb.events.values():
            if e.component:
                self.known["%s of %s" % (e.name, e.component)] = ("event", "?", None)

    def describe(self, path):
        return self.known.get(path)

    def signature(self, path):
        """The arguments the database declares for activity ``path`` (checked at load)."""
        return self.signatures.get(path)


def _read(path):
    with open(path) as f:
        return f.read()


def _errors(e):
    return getattr(e, "errors", None) or [e]


class CatalogResolver:
    """Answers the checker's questions from a checked mission: its database and the
    interfaces of its components (``obsw.pluto.names.Catalog``)."""

    def __init__(self, mission):
        from obsw.pluto.names import Catalog

        self.catalog = Catalog(mission.sdb, list(mission.interfaces.values()))

    def describe(self, path):
        from obsw.pluto.names import CODE, KIND, UNIT

        e = self.catalog.find(path)
        if e is None:
            return None
        if e[KIND] == "parameter":
            return ("parameter", e[CODE] or "?", e[UNIT])
        return (e[KIND], None, None)

    def signature(self, path):
        from obsw.pluto.names import KIND, SIGNATURE

        e = self.catalog.find(path)
        return e[SIGNATURE] if e is not None and e[KIND] == "activity" else None


def _mission_resolver(folder):
    from obsw_host.mission.check import load as load_mission
    from obsw_host.mission.errors import MissionError

    try:
        return CatalogResolver(load_mission(folder))
    except MissionError as e:
        raise UserError("mission %s does not load: %s" % (folder, e),
                        expected="a mission `obsw mission check` passes") from None  # fmt: skip


def check_cmd(args):
    resolver = None
    given = [o for o in ("sdb", "system", "mission") if getattr(args, o, None)]
    if getattr(args, "syntax_only", False):
        given.append("syntax-only")
    if len(given) > 1:
        raise UserError("--%s and --%s: one of them" % (given[0], given[1]),
                        expected="one source of references, or --syntax-only")  # fmt: skip
    if getattr(args, "syntax_only", False):
        try:
            parse(_read(args.file))
        except PlutoError as e:
            print("%s:%d:%d: %s: %s" % (args.file, e.line, e.col, e.kind, e.msg))
            return 1
        print("%s: ok (syntax)" % args.file)
        return 0
    if getattr(args, "mission", None):
        resolver = _mission_resolver(args.mission)
    elif args.sdb:
        from obsw_host.sample import load_sdb

        resolver = SdbResolver(load_sdb(args.sdb))
    elif args.system:
        resolver = _system(args.system, read_json(args.system, "system file"))
    try:
        load(_read(args.file), resolver)
    except PlutoError as e:
        for x in _errors(e):
            print("%s:%d:%d: %s: %s" % (args.file, x.line, x.col, x.kind, x.msg))
        return 1
    print("%s: ok" % args.file)
    return 0


def _system(path, spec):
    try:
        return SimulatedSystem(spec)
    except SystemSpecError as e:
        raise UserError("%s: %s" % (path, e)) from None


def _json_value(v):
    if isinstance(v, Quantity):
        return {"value": v.value, "unit": v.unit}
    return v


def _arg(text):
    name, _, value = text.partition("=")
    try:
        return name.strip(), json.loads(value)
    except ValueError:
        return name.strip(), value


def run_cmd(args):
    spec = read_json(args.system, "system file") if args.system else {}
    if args.system:
        _system(args.system, spec)  # a description it cannot play is the user's, said at once
    arguments = {}
    for a in args.arg:  # a value with units as in the system file: {"value": 3, "unit": "V"}
        name, value = _arg(a)
        try:
            arguments[name] = value_of(value, "--arg " + name)
        except SystemSpecError as e:
            raise UserError(str(e)) from None

    def show(t, line, what):
        print("t=%-8g line %-4d %s" % (t, line, what), file=sys.stderr)

    trace = dry_run(_read(args.file), spec, arguments, None if args.quiet else show)
    print(json.dumps(trace, indent=2, default=_json_value))
    return 0 if trace["accept"] and trace["status"] == "confirmed" else 1


def engine_cmd(args):
    from obsw_host.obcp import run_args

    return run_args(args)
