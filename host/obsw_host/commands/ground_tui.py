"""The implementations of `obsw ground watch` (rich) and `obsw ground console` (prompt_toolkit),
imported only when one of them runs (`ground_console` declares their arguments); the module
text of `ground_console` says what they do."""

import argparse
import json
import os
import shlex
import sys
import time

from prompt_toolkit import PromptSession
from prompt_toolkit.completion import Completer, Completion
from prompt_toolkit.history import FileHistory
from rich.console import Console, Group
from rich.live import Live
from rich.table import Table

from obsw_host.commands import session
from obsw_host.errors import user_message
from obsw_host.mission import ids as mission_ids
from obsw_host.obc.state import default_state
from obsw_host.pus import catalog
from obsw_host.pus.display import Picture, number
from obsw_host.pus.tm_fanout import LINGER

HISTORY_FILE = "ground-history"
_LIMIT_STYLES = {"ok": "green", "warning": "yellow", "critical": "bold red", "out of range": "red"}
_SEVERITY_STYLES = {"info": "", "low": "cyan", "medium": "yellow", "high": "bold red"}
CONSOLE_KEYS = ("func", "action", "history", "once", "count", "every", "seconds")


# ------------------------------------------------------------------------------ watch


def render(picture, los_after):
    """The picture as rich tables: values, events, commands; at loss of signal the values are
    dimmed and their limit column says so. What came from the spacecraft is escaped: no
    control character and no rich markup of its own reaches the terminal."""
    from rich.markup import escape as markup

    signal, lost = picture.signal(los_after)
    title = "current values (%s)" % signal
    values = Table(title=title, expand=True, title_justify="left")
    for column in ("parameter", "value", "unit", "limit", "on-board time (UTC)"):
        values.add_column(column)
    for name, v in picture.values.items():
        limit = v["limit"]
        style = "dim" if lost else _LIMIT_STYLES.get(limit, "")
        value = number(v["value"])
        limit = "stale (%s)" % (limit or "-") if lost else (limit or "-")
        values.add_row(markup(name), markup(value), v["unit"], limit, v["time"],
                       style=style or None)  # fmt: skip
    events = Table(title="latest events", expand=True, title_justify="left")
    for column in ("time (UTC)", "event", "severity", "data"):
        events.add_column(column)
    for e in picture.events:
        style = _SEVERITY_STYLES.get(e["severity"], "") or None
        events.add_row(e["time"], markup(e["event"]), markup(str(e["severity"])),
                       markup(e["data"]), style=style)  # fmt: skip
    commands = Table(title="commands", expand=True, title_justify="left")
    for column in ("request", "apid", "seq", "verification"):
        commands.add_column(column)
    for row in reversed(picture.commands.values()):
        stages = ", ".join(row["stages"]) or "waiting"
        style = "red" if "failed" in stages else None
        commands.add_row(
            row["request"], str(row["apid"]), str(row["seq_count"]), stages, style=style
        )
    return Group(values, events, commands)


def _ask_housekeeping(g, picture):
    """One-shot reports of every structure the database declares (TC[3,27]); waits for them."""
    if g.hk is None:
        return
    sent = []
    for hk in g.sdb.housekeeping:
        tx = g.hk.one_shot(g.apid, [hk["sid"]])
        picture.sent(tx.tc)
        sent.append(tx)
    deadline = time.monotonic() + g.timeout
    while any(not tx.done for tx in sent) and time.monotonic() < deadline:
        g.poll(max(0.0, min(0.2, deadline - time.monotonic())))


def watch(args):
    frames = 1 if args.once else args.count
    with session.ground(args) as g:
        picture = Picture(g.sdb, config=g.proc.config)
        g.proc.listeners.append(lambda tm, decoded, tx: picture.feed(tm, decoded))
        g.subscribe()
        _ask_housekeeping(g, picture)
        if args.json:
            show = lambda: print(json.dumps(picture.snapshot(args.los)), flush=True)  # noqa: E731
            rc = _frames(g, args, frames, show)
        else:
            console = Console()
            if frames is not None or not console.is_terminal:
                rc = _frames(g, args, frames, lambda: console.print(render(picture, args.los)))
            else:
                with Live(render(picture, args.los), console=console, auto_refresh=False) as live:
                    rc = _frames(
                        g, args, None, lambda: live.update(render(picture, args.los), refresh=True)
                    )
        if picture.received == 0:
            print(
                "no TM from %s:%s: is `obsw obc serve` running there?" % g.target,
                file=sys.stderr,
            )
            return 1
        return rc


def _frames(g, args, frames, show):
    """Show a frame every ``args.every`` seconds until ``frames`` were shown or time is up."""
    now = time.monotonic
    end = None if args.seconds is None else now() + args.seconds
    subscribed = now()
    shown = 0
    while True:
        show()
        shown += 1
        if frames is not None and shown >= frames:
            return 0
        due = now() + args.every
        while now() < due:
            if end is not None and now() >= end:
                return 0
            g.poll(max(0.0, min(0.2, due - now())))
        if now() - subscribed > LINGER / 3:
            g.subscribe()
            subscribed = now()


# ------------------------------------------------------------------------------ console


def history_path(args, ids):
    """The console's history file: ``--history``, else ``ground-history`` in the mission's
    state folder (its mission file's ``state``; without a mission file, the user state folder
    of the database's mission name)."""
    if args.history:
        return args.history
    state = getattr(getattr(ids, "config", None), "state", None)
    if not state:
        state = default_state(getattr(ids.sdb, "mission", "") or "obsw")
    return os.path.join(state, HISTORY_FILE)


def _subcommands(parser):
    """The subcommand parsers of ``parser`` by name ({} if it has none)."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return action.choices
    return {}


def _options(parser):
    return [o for a in parser._actions for o in a.option_strings if o.startswith("--")]


class GroundCompleter(Completer):
    """Completion of `obsw ground` commands (from the parser) and of the database's names."""

    def __init__(self, ground_parser, sdb):
        self.root = ground_parser
        self.names = []
        if sdb is not None:
            self.names += [r["name"] for r in catalog.parameters(sdb)]
            self.names += [r["name"] for r in catalog.function_rows(sdb)]
            self.names += [r["name"] for r in catalog.events(sdb)]
        self.assignable = [r["name"] + "=" for r in catalog.parameters(sdb)] if sdb else []
        self.arguments = {}
        if sdb is not None:
            for r in catalog.function_rows(sdb):
                names = [a.split(":")[0].strip() for a in r["arguments"].split(",") if a]
                self.arguments[r["name"]] = [n + "=" for n in names]
            for f in sdb.functions.values():  # a labelled argument completes with its labels
                names = {a[0]: a[1] for a in f.arguments}
                for aid, labels in (getattr(f, "labels", None) or {}).items():
                    self.arguments.setdefault(f.name, []).extend(
                        "%s=%s" % (names[aid], label) for label in labels.values()
                    )

    def candidates(self, words):
        """What may follow ``words`` (the words before the one being typed)."""
        parser = self.root
        for w in words:
            parser = _subcommands(parser).get(w, parser)
        out = sorted(_subcommands(parser)) + _options(parser)
        if words and words[-1] in self.arguments:
            out += self.arguments[words[-1]]
        if any(w in self.arguments for w in words[-2:]):  # a function's arguments follow
            return out
        if "set" in words:
            out += self.assignable
        if words:
            out += self.names
        if not words:
            out += ["help", "exit"]
        return out

    def get_completions(self, document, complete_event):
        before = document.text_before_cursor
        try:
            words = shlex.split(before)
        except ValueError:
            return
        current = "" if not before or before[-1].isspace() else (words.pop() if words else "")
        seen = set()
        for c in self.candidates(words):
            if c.startswith("-") and not current.startswith("-"):
                continue  # options only once a dash is typed
            if c.startswith(current) and c not in seen:
                seen.add(c)
                yield Completion(c, start_position=-len(current))


def _ground_parser():
    from obsw_host.cli import build_parser

    return _subcommands(build_parser("ground"))["ground"]


def run_line(line, base, parser):
    """Run one console line as `obsw ground LINE` with the console's own options; returns
    the exit status (2 for a mistake, which is printed as one line)."""
    try:
        words = shlex.split(line)
    except ValueError as e:
        print("obsw ground: %s" % e, file=sys.stderr)
        return 2
    as_json = "--json" in words
    words = [w for w in words if w != "--json"]
    ns = argparse.Namespace(**base)
    try:
        args = parser.parse_args(words, namespace=ns)
    except SystemExit as e:  # argparse printed the usage error or the help
        return e.code if isinstance(e.code, int) else 2
    args.json = base.get("json", False) or as_json
    try:
        return args.func(args) or 0
    except KeyboardInterrupt:
        print("(interrupted)", file=sys.stderr)
        return 130
    except Exception as e:
        message = user_message(e)
        if message is None or base.get("debug"):
            raise
        print("obsw ground: %s" % message, file=sys.stderr)
        return 1 if isinstance(e, TimeoutError) else 2


def console(args):
    with session.ground(args) as g:  # the database and the target the console's commands use
        sdb, target = g.sdb, g.target
    parser = _ground_parser()
    base = {k: v for k, v in vars(args).items() if k not in CONSOLE_KEYS}
    interactive = sys.stdin.isatty() and sys.stdout.isatty()
    if not interactive:
        status = 0
        for line in sys.stdin:
            if line.strip() in ("exit", "quit"):
                break
            if line.strip() and not line.lstrip().startswith("#"):
                status = run_line(line, base, parser) or status
        return status
    path = history_path(args, mission_ids.from_args(args))
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    prompt = PromptSession(
        history=FileHistory(path),
        completer=GroundCompleter(parser, sdb),
        complete_while_typing=False,
    )
    print(
        "obsw ground console on %s:%d (Tab completes; `help`; Ctrl-D leaves; history in %s)"
        % (target[0], target[1], path)
    )
    while True:
        try:
            line = prompt.prompt("%s> " % (getattr(sdb, "mission", "") or "obsw"))
        except KeyboardInterrupt:
            continue
        except EOFError:
            return 0
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        if line in ("exit", "quit"):
            return 0
        if line == "help":
            parser.print_help()
            continue
        run_line(line, base, parser)
