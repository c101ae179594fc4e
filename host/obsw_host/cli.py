"""The `obsw` command line: one subcommand per area, each in obsw_host.commands."""

import argparse
import importlib
import sys

# Each module has add_parser(subparsers); the chosen subcommand's function gets the parsed args
# and returns the exit status. Modules are imported lazily so one area's extras stay optional.
COMMANDS = (
    "demo",
    "packet",
    "obc",
    "ground",
    "obcp",
    "il",
    "spacecan",
    "frames",
    "cfdp",
    "pluto",
    "board",
    "yamcs",
)


def build_parser():
    parser = argparse.ArgumentParser(
        prog="obsw", description="Open onboard software for CubeSats: host tools, OBC and ground."
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name in COMMANDS:
        importlib.import_module("obsw_host.commands." + name).add_parser(sub)
    return parser


def main(argv=None):
    args = build_parser().parse_args(argv)
    try:
        return args.func(args) or 0
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    sys.exit(main())
