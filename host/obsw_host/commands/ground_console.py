"""`obsw ground watch` and `obsw ground console`: the operator's live view and interactive
console against a running `obsw obc serve`.

    obsw ground watch                   live table: current values with units and limit state,
                                        the latest events, commands and their verification
    obsw ground watch --once            one frame after asking for every housekeeping report
    obsw ground watch --count 5 --every 2 --json     five frames, as JSON, two seconds apart
    obsw ground console                 interactive: any `obsw ground` command on a line, with
                                        completion of commands and of the database's parameter,
                                        function and event names, and a history per mission

The console's history file is ``ground-history`` in the mission's state folder (the mission
file's ``state``), or ``--history FILE``. With standard input not a terminal, the console reads
one command a line (for scripts) and keeps no history.
"""

import argparse

from obsw_host.commands import arguments

LOS_AFTER = 5.0  # seconds without TM before `watch` shows loss of signal

# the console and the live view import their libraries (prompt_toolkit, rich) in
# ground_tui, only when they run: every other command starts without them


def add_to_ground(s):
    x = s.add_parser(
        "watch",
        help="live table of current values, events and commands (rich)",
        description="A live view until Ctrl-C: the current value of every parameter reported "
        "(housekeeping, parameter reports) with its unit and limit state from the database, "
        "the latest events, and commands with their verification stages.",
    )
    x.add_argument("--once", action="store_true", help="print one frame and exit")
    x.add_argument("--count", type=arguments.count, help="print this many frames and exit")
    x.add_argument("--every", type=arguments.seconds, default=1.0, help="seconds between frames")
    x.add_argument("--seconds", type=arguments.seconds, help="stop after this many seconds")
    x.add_argument(
        "--los",
        type=arguments.seconds,
        default=LOS_AFTER,
        help="seconds without TM before the view shows loss of signal and marks every value "
        "as stale (default %g)" % LOS_AFTER,
    )
    x.set_defaults(func=_watch)
    x = s.add_parser(
        "console",
        help="interactive console with completion and history (prompt_toolkit)",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    x.add_argument("--history", metavar="FILE", help="history file (default: see above)")
    x.set_defaults(func=_console)


def _watch(args):
    from obsw_host.commands import ground_tui

    return ground_tui.watch(args)


def _console(args):
    from obsw_host.commands import ground_tui

    return ground_tui.console(args)
