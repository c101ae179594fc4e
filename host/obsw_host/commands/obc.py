"""`obsw obc serve [MISSION]`: the onboard computer of a mission folder (or its mission file).

MISSION is a mission folder or its file; without it, $OBSW_MISSION or a mission.json in the
working folder or above (the sample spacecraft is `examples/sample`). The whole folder is
checked first (`obsw mission check`): a mistake stops the start with one line per problem,
exit status 2, before any process starts. Then the PUS services, the CFDP entity, the OBCP
engine, the SpaceCAN master and the mission's components run in the processes the mission
file names, started and watched by the platform manager. Its state lives in the mission's
state folder (default `$XDG_STATE_HOME/obsw/<mission>`), locked while it runs: a second `obsw
obc serve` of the same mission refuses. `obsw obc reset [MISSION]` clears that folder; `obsw obc
config [MISSION]`
prints the configuration and its topology as the OBC understands them. `--process NAME` runs
one process of the configuration (what the platform manager starts).
"""

import argparse
import json
import os
import sys

from obsw_host.errors import UserError
from obsw_host.mission.config import ConfigError
from obsw_host.mission.config import load as load_config
from obsw_host.mission.folder import locate
from obsw_host.obc import service
from obsw_host.obc.state import StateLock, StateLocked
from obsw_host.obc.state import reset as reset_state
from obsw_host.obc.topology import Topology

EXIT_REFUSED = 2
MISSION_HELP = "mission folder or file (default: $OBSW_MISSION, or a mission.json here or above)"


def add_parser(sub):
    p = sub.add_parser("obc", help="the onboard computer", description=__doc__)
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True
    x = s.add_parser("serve", help="run the onboard computer until Ctrl-C")
    add_serve_arguments(x)
    x.set_defaults(func=serve)
    c = s.add_parser("config", help="print the mission configuration and topology as understood")
    c.add_argument("config", nargs="?", help=MISSION_HELP)
    c.add_argument("--state", help="the state folder (default: the mission's)")
    c.set_defaults(func=show)
    t = s.add_parser("status", help="the running OBC's processes: pids, uptime, restarts")
    t.add_argument("config", nargs="?", help=MISSION_HELP)
    t.add_argument("--state", help="the state folder (default: the mission's)")
    t.set_defaults(func=status)
    r = s.add_parser("reset", help="clear the mission's state folder (refused while it runs)")
    r.add_argument("config", nargs="?", help=MISSION_HELP)
    r.add_argument("--state", help="the state folder (default: the mission's)")
    r.set_defaults(func=reset)
    i = s.add_parser(
        "install-service",
        help="write the systemd unit that runs this mission's OBC (Type=notify, WatchdogSec)",
    )
    i.add_argument("config", nargs="?", help=MISSION_HELP)
    i.add_argument("--state", help="the state folder (default: the mission's, else %s)" % (
        service.DEFAULTS["state"]))  # fmt: skip
    i.add_argument("--user", help="the user the OBC runs as (default %(default)s)",
                   default=service.DEFAULTS["user"])  # fmt: skip
    i.add_argument("--obsw", help="the obsw command (default: the one running now)")
    i.add_argument("--watchdog-sec", type=int, default=service.DEFAULTS["watchdog_sec"],
                   help="systemd's WatchdogSec= (default %(default)s s)")  # fmt: skip
    i.add_argument("--root", default="/", help="write under this folder instead of / (images)")
    i.add_argument("--dry-run", action="store_true", help="print the unit, write nothing")
    i.set_defaults(func=install_service)


def add_serve_arguments(x):
    x.add_argument("config", nargs="?", help=MISSION_HELP)
    x.add_argument("--state", help="folder for context, files and packet stores (default: the "
                   "configuration's 'state', or $XDG_STATE_HOME/obsw/<mission>)")  # fmt: skip
    x.add_argument("--il-dir", help="interaction layer name directory (default STATE/il)")
    x.add_argument("--process", help="run only this process of the configuration")
    x.add_argument("--parent", type=int, help=argparse.SUPPRESS)
    x.add_argument("--quiet", action="store_true", help="print nothing but errors")


def load(args):
    config = load_config(args.config)
    if getattr(args, "state", None):
        config.state = os.path.abspath(args.state)
        config.il_directory = os.path.join(config.state, "il")
    if getattr(args, "il_dir", None):
        config.il_directory = os.path.abspath(args.il_dir)
    return config


def check_mission(path):
    """The problems of the whole mission folder at ``path`` (``obsw mission check``)."""
    from obsw_host.mission.check import check  # jsonschema and the PLUTO checker: parent only

    return check(locate(path))[1]


def refused_unchecked(path):
    """None if the mission at ``path`` passes ``obsw mission check``, else ``EXIT_REFUSED``
    after one line per problem: what works on a mission checks it first."""
    try:
        problems = check_mission(path)
    except (ConfigError, UserError) as e:
        return _refuse(e)
    for problem in problems:
        print(problem, file=sys.stderr, flush=True)
    return EXIT_REFUSED if problems else None


def ports_in_use(topology):
    """The UDP ports this OBC binds (PUS, CFDP, the frame processor's inputs) that another
    program holds now: ``["5010 (pus)", ...]``."""
    import socket

    ids, host = topology.ids, topology.config.host
    wanted = []
    if topology.runs("pus"):
        wanted.append(("pus", ids.ports.pus))
    if topology.runs("cfdp"):
        wanted.append(("cfdp", ids.ports.cfdp))
    if topology.runs("frames"):
        wanted += [("tm", ids.ports.tm), ("playback", ids.ports.playback)]
    taken = []
    for name, port in wanted:
        s = socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET, socket.SOCK_DGRAM)
        try:
            s.bind((host, port))
        except OSError:
            taken.append("%d (%s)" % (port, name))
        finally:
            s.close()
    return taken


def _refuse(text):
    print("obsw obc: %s" % text, file=sys.stderr, flush=True)
    return EXIT_REFUSED


def serve(args):
    def out(text):
        if not args.quiet:
            print(text, file=sys.stderr, flush=True)

    try:
        if not args.process:  # the platform manager checks the whole folder, once
            problems = check_mission(args.config)
            if problems:
                for problem in problems:  # one line each: FILE: $.path: what; expected ...
                    print(problem, file=sys.stderr, flush=True)
                return EXIT_REFUSED
        config = load(args)
        if config.runs("frames"):  # refuse at once, before any process starts
            from obsw_host.frames import policy

            policy.check(config)
        topology = Topology(config)
        if args.process:
            return _serve_process(topology, args, out)
        topology.check()  # component modules import, before anything starts
    except (ConfigError, UserError) as e:
        return _refuse(e)
    try:
        lock = StateLock(config.state).acquire()
    except StateLocked as e:
        return _refuse(e)
    try:
        taken = ports_in_use(topology)  # after the lock: another OBC of this state is named
        if taken:
            return _refuse(
                UserError(
                    "UDP port%s %s on %s in use (another program, or an OBC of this mission with "
                    "another state folder?)"
                    % ("s" if len(taken) > 1 else "", ", ".join(taken), config.host),
                    expected="free ports: stop it, or move this OBC's with $OBSW_PORT_BASE or "
                    "the mission's `ports`",
                )
            )
        return _boot(args, config, topology, out)
    except KeyboardInterrupt:
        return 0
    finally:
        lock.release()


def _boot(args, config, topology, out):
    """The boot selector: run the platform manager on the software the boot record names
    (``obsw_host.update.slots``), and again after every update step that changes it."""
    from obsw_host.obc import memtrace
    from obsw_host.obc.platform import PlatformManager, stop_on_signals
    from obsw_host.update.component import software_of
    from obsw_host.update.slots import FACTORY

    memtrace.install("platform")  # only with $OBSW_TRACEMALLOC (the soak benchmark)
    done = stop_on_signals()  # between two runs too
    software = software_of(config)
    max_starts = int(topology.section("update")["max_starts"])
    while not done.is_set():
        slot, trial = software.choose(max_starts)
        code, mission = software.code(slot)
        run = topology
        if mission is not None:
            try:
                run = _slot_topology(config, mission)
            except (ConfigError, UserError) as e:
                software.fall_back("its mission is refused: %s" % e)
                continue
        out("%s: version %s (slot %s%s), processes %s, state in %s (Ctrl-C stops)" % (
            run.config.name, software.version(slot), slot, ", on trial" if trial else "",
            ", ".join(run.config.processes), config.state))  # fmt: skip
        outcome = PlatformManager(run, out=out, software=software, slot=slot, code=code,
                                  trial=trial).serve(done)  # fmt: skip
        if outcome is True:
            return 0
        if outcome is False:
            if slot == FACTORY:
                return _refuse("every process stopped: the OBC cannot run this mission")
            software.fall_back("every process of version %s stopped" % software.version(slot))
    return 0


def _slot_topology(config, mission):
    """The topology of a slot's mission folder, in the OBC's own state folder."""
    problems = check_mission(mission)
    if problems:
        raise UserError(problems[0])
    slot = load_config(mission)
    slot.state, slot.il_directory = config.state, config.il_directory
    if slot.runs("frames"):
        from obsw_host.frames import policy

        policy.check(slot)
    return Topology(slot).check()


def _serve_process(topology, args, out):
    """One process of the topology. One that cannot be built says why in one line: status 2
    for a configuration error (final: the platform manager does not restart it), else 1."""
    from obsw_host.obc import memtrace
    from obsw_host.obc.assembly import ObcProcess

    memtrace.install(args.process)  # only with $OBSW_TRACEMALLOC (the soak benchmark)
    try:
        process = ObcProcess(topology, args.process, out=out)
    except ConfigError as e:
        return _refuse("process %s: %s" % (args.process, e))
    except Exception as e:  # one line, not a traceback; the platform manager counts it
        print("obsw obc: process %s cannot start: %s: %s" % (
            args.process, type(e).__name__, e), file=sys.stderr, flush=True)  # fmt: skip
        return 1
    try:
        process.serve(parent=args.parent)
    except KeyboardInterrupt:
        pass
    return 0


def show(args):
    refused = refused_unchecked(args.config)
    if refused is not None:
        return refused
    try:
        config = load(args)
        topology = Topology(config)
    except ConfigError as e:
        return _refuse(e)
    print(json.dumps({
        "name": config.name, "path": config.path, "sdb": config.sdb_path, "host": config.host,
        "state": config.state, "il_directory": config.il_directory,
        "processes": config.processes, "platform": config.platform,
        "topology": topology.describe(),
    }, indent=2))  # fmt: skip
    return 0


def _alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process: there all the same
        return True
    return True


def _duration(seconds):
    s = int(seconds)
    if s < 120:
        return "%d s" % s
    if s < 7200:
        return "%d min" % (s // 60)
    return "%d h %02d min" % (s // 3600, s % 3600 // 60)


def status(args):
    """The processes of the OBC running this mission, as its platform manager last wrote
    them (``STATE/platform.json``); exit status 1 when it is not running."""
    import time

    from obsw_host.obc.platform import STATUS_FILE

    try:
        config = load(args)
    except ConfigError as e:
        return _refuse(e)
    path = os.path.join(config.state, STATUS_FILE)
    try:
        with open(path) as f:
            st = json.load(f)
    except (OSError, ValueError):
        print("%s: not running (no status in %s)" % (config.name, config.state))
        return 1
    if not st.get("running") or not _alive(int(st.get("manager", 0))):
        print("%s: not running (last status %s)" % (config.name, time.strftime(
            "%Y-%m-%d %H:%M:%S", time.localtime(st.get("written", 0)))))  # fmt: skip
        return 1
    if args.json:
        print(json.dumps(st, indent=2))
        return 0
    now = time.time()
    print("%s: platform manager pid %d" % (config.name, st["manager"]))
    rows = [("process", "pid", "state", "uptime", "restarts", "runs")]
    for p in st["processes"]:
        up = _duration(now - p["started"]) if p.get("started") and p["state"] == "up" else "-"
        state = p["state"] + (" (%s)" % p["why"] if p.get("why") else "")
        rows.append((p["name"], str(p["pid"]), state, up, str(p["restarts"]),
                     ", ".join(p["runs"])))  # fmt: skip
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]) - 1)]
    for r in rows:
        print("  ".join(x.ljust(w) for x, w in zip(r, widths)) + "  " + r[-1])
    return 0


def reset(args):
    try:
        config = load(args)
        removed = reset_state(config.state)
    except ConfigError as e:
        return _refuse(e)
    except StateLocked as e:
        return _refuse("%s: not reset" % e)
    print(("removed %s" if removed else "nothing to remove at %s") % config.state)
    return 0


def install_service(args):
    refused = refused_unchecked(args.config)
    if refused is not None:  # no unit for a mission that would not start
        return refused
    try:
        config = load_config(args.config)
        state = args.state or (config.state if "state" in config.doc else None)
        text = service.unit_text(
            mission=os.path.abspath(config.path),
            obsw=args.obsw
            or os.path.join(os.path.dirname(os.path.abspath(sys.executable)), "obsw"),  # fmt: skip
            state=os.path.abspath(state) if state else None,
            user=args.user,
            watchdog_sec=args.watchdog_sec,
        )
    except (ConfigError, UserError, ValueError) as e:
        return _refuse(e)
    if args.dry_run:
        print(text, end="")
        return 0
    try:
        path = service.install(text, args.root)
    except OSError as e:
        return _refuse("cannot write the unit under %s: %s" % (args.root, e))
    print("wrote %s" % path)
    if args.root == "/":
        print("now: systemctl daemon-reload && systemctl enable --now %s" % service.UNIT_NAME)
    return 0


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m obsw_host.obc", description=__doc__)
    add_serve_arguments(p)
    from obsw_host import logs

    logs.setup()  # the level obsw --log-level gave the parent ($OBSW_LOG_LEVEL)
    return serve(p.parse_args(argv))
