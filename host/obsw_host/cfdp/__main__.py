"""``python -m obsw_host.cfdp put|get|status|serve ...``: the same as ``obsw cfdp``."""

import argparse
import sys

from obsw_host.commands import cfdp


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m obsw_host.cfdp", description=cfdp.__doc__)
    sub = p.add_subparsers(dest="command")
    cfdp.add_parser(sub)
    args = p.parse_args(["cfdp"] + list(sys.argv[1:] if argv is None else argv))
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
