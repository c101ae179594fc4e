"""`obsw obc serve [CONFIG]`: the onboard computer of a mission configuration file.

Without CONFIG it runs the sample spacecraft: every PUS service (1-23) on UDP 5010, the CFDP
entity on 5100, the OBCP engine, the SpaceCAN master with the CPDU nodes (simulated on
virtual buses), and the sample solar panel, in processes started and watched by the platform
manager. `--process NAME` runs one process of the configuration (what the platform manager
starts); `obsw obc config [CONFIG]` prints the configuration as the OBC understands it.
"""

import argparse
import json
import os
import sys
import tempfile


def add_parser(sub):
    p = sub.add_parser("obc", help="the onboard computer", description=__doc__)
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True
    x = s.add_parser("serve", help="run the onboard computer until Ctrl-C")
    add_serve_arguments(x)
    x.set_defaults(func=serve)
    c = s.add_parser("config", help="print the mission configuration as understood")
    c.add_argument("config", nargs="?", help="mission configuration JSON (default: the sample)")
    c.set_defaults(func=show)


def add_serve_arguments(x):
    x.add_argument("config", nargs="?", help="mission configuration JSON (default: the sample)")
    x.add_argument("--state", help="folder for context, files and packet stores (default: the "
                   "configuration's 'state', or a folder under the temp directory)")  # fmt: skip
    x.add_argument("--il-dir", help="interaction layer name directory (default STATE/il)")
    x.add_argument("--process", help="run only this process of the configuration")
    x.add_argument("--parent", type=int, help=argparse.SUPPRESS)
    x.add_argument("--quiet", action="store_true", help="print nothing but errors")


def load(args):
    from obsw_host.obc.config import load as load_config

    config = load_config(args.config)
    if getattr(args, "state", None):
        config.state = os.path.abspath(args.state)
        config.il_directory = os.path.join(config.state, "il")
    elif "state" not in config.doc:
        config.state = os.path.join(
            tempfile.gettempdir(), "obsw-%s-%d" % (config.name, os.getuid())
        )
        config.il_directory = os.path.join(config.state, "il")
    if getattr(args, "il_dir", None):
        config.il_directory = os.path.abspath(args.il_dir)
    return config


def serve(args):
    from obsw_host.obc.config import ConfigError

    def out(text):
        if not args.quiet:
            print(text, file=sys.stderr, flush=True)

    try:
        config = load(args)
        if config.runs("frames"):  # refuse at once, before any process starts
            from obsw_host.frames import policy

            policy.check(config)
        if args.process:
            from obsw_host.obc.assembly import ObcProcess

            ObcProcess(config, args.process, out=out).serve(parent=args.parent)
        else:
            from obsw_host.obc.platform import PlatformManager

            out("%s: processes %s, state in %s (Ctrl-C stops)" % (
                config.name, ", ".join(config.processes), config.state))  # fmt: skip
            PlatformManager(config, out=out).serve()
    except (ConfigError, KeyError) as e:
        print("obsw obc: %s" % e, file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        pass
    return 0


def show(args):
    from obsw_host.obc.config import ConfigError

    try:
        config = load(args)
    except ConfigError as e:
        print("obsw obc: %s" % e, file=sys.stderr)
        return 2
    print(json.dumps({
        "name": config.name, "path": config.path, "sdb": config.sdb_path, "host": config.host,
        "state": config.state, "il_directory": config.il_directory,
        "processes": config.processes, "platform": config.platform,
    }, indent=2))  # fmt: skip
    return 0


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m obsw_host.obc", description=__doc__)
    add_serve_arguments(p)
    from obsw_host import logs

    logs.setup()  # the level obsw --log-level gave the parent ($OBSW_LOG_LEVEL)
    return serve(p.parse_args(argv))
