"""The `obsw` command line: one subcommand per area, each in obsw_host.commands.

Errors have one style everywhere: a user mistake (``obsw_host.errors.user_message``) prints one
line, ``obsw COMMAND: what was wrong; expected ...``, and exits with status 2 (1 when nothing
answered in time); ``--debug`` shows the traceback instead. ``--json`` and ``--debug`` are
accepted anywhere on the line. ``--log-level`` sets the level of the processes' logs.
"""

import argparse
import importlib
import sys

from obsw_host import logs
from obsw_host.errors import user_message

# Each module has add_parser(subparsers); the chosen subcommand's function gets the parsed args
# and returns the exit status. Only the chosen command's module is imported (the others get a
# placeholder with their help line), so one area's extras stay optional and startup is quick.
# in the order a team works: its mission, the OBC that flies it, the ground that operates it,
# then files, procedures, links, mission control, the boards and updates, then the tools
COMMANDS = {
    "mission": "check, create or upgrade a mission folder",
    "obc": "on-board processes",
    "ground": "send PUS requests to an on-board process, monitor its TM",
    "cfdp": "CFDP file transfer (put, get, status, serve)",
    "obcp": "PLUTO OBCPs on board (PUS service 18)",
    "pluto": "check or dry-run PLUTO procedures",
    "yamcs": "mission control with Yamcs: XTCE, instance, server",
    "frames": "CCSDS TC/TM frames, CLTUs, frame processor",
    "keys": "SDLS keys: key files, OTAR, key and SA management over the link",
    "board": "Pyboard firmware for the reconfiguration module",
    "update": "signed software updates of the OBC: build, push, activate, roll back",
    "spacecan": "SpaceCAN bus tools",
    "il": "interaction layer: serve and use components",
    "pus": "PUS-C: the standard's message types the OBC serves",
    "packet": "decode or encode space packets",
    "ops": "operations across passes: pass prediction, pass plans",
}
ANYWHERE = ("--json", "--debug")  # flags accepted at any position before "--"
USAGE_ERROR = 2
NO_ANSWER = 1


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors: ``obsw ground ping: error: ... (see --help)``."""

    def error(self, message):
        self.exit(
            USAGE_ERROR, "%s: error: %s (see `%s --help`)\n" % (self.prog, message, self.prog)
        )


def version():
    try:
        from importlib.metadata import version as dist_version

        return dist_version("obsw")
    except Exception:  # not installed as a distribution: running from the source tree
        return "unknown"


class _Version(argparse.Action):
    """``--version``: the distribution's version is looked up only when asked for (reading
    the package metadata costs every other command's start-up time)."""

    def __call__(self, parser, namespace, values, option_string=None):
        print("obsw " + version())
        parser.exit()


def build_parser(only=None):
    """The parser; with ``only`` (a command name), only that command's module is imported."""
    parser = Parser(
        prog="obsw", description="Open onboard software for CubeSats: host tools, OBC and ground."
    )
    parser.add_argument("--version", action=_Version, nargs=0, help="show the version and exit")
    parser.add_argument(
        "--debug", action="store_true", help="show the traceback of an error (also anywhere)"
    )
    parser.add_argument(
        "--json", action="store_true", help="print JSON for scripts (also anywhere on the line)"
    )
    parser.add_argument(
        "--log-level",
        choices=("debug", "info", "warning", "error"),
        help="level of the on-board processes' logs on stderr (default info)",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name, text in COMMANDS.items():
        if only is None or only == name:
            importlib.import_module("obsw_host.commands." + name).add_parser(sub)
        else:
            sub.add_parser(name, help=text)
    return parser


def _command(argv):
    """The command named on the line, or None (then every command's module is loaded)."""
    for i, word in enumerate(argv):
        if word == "--log-level":
            continue
        if i and argv[i - 1] == "--log-level":
            continue
        if not word.startswith("-"):
            return word if word in COMMANDS else None
    return None


def _split_anywhere(argv):
    """``argv`` without the flags of ANYWHERE, and the set of those present."""
    rest, found = [], set()
    for i, word in enumerate(argv):
        if word == "--":
            rest.extend(argv[i:])
            break
        if word in ANYWHERE:
            found.add(word)
        else:
            rest.append(word)
    return rest, found


def main(argv=None):
    argv = list(sys.argv[1:] if argv is None else argv)
    argv, found = _split_anywhere(argv)
    args = build_parser(_command(argv)).parse_args(argv)
    args.json = getattr(args, "json", False) or "--json" in found
    debug = args.debug or "--debug" in found
    logs.setup(args.log_level)
    try:
        return args.func(args) or 0
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:  # the reader went away (`obsw ... | head`): nothing more to say
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except Exception as e:
        text = user_message(e)
        if text is None or debug:
            raise
        print("obsw %s: %s" % (args.command, text), file=sys.stderr)
        return NO_ANSWER if isinstance(e, TimeoutError) else USAGE_ERROR


if __name__ == "__main__":
    sys.exit(main())
