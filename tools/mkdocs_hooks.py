"""MkDocs hook: the command reference page, generated at build time from `obsw`'s own parsers.

Every command and option of `obsw` appears on docs/reference/cli.md (site path) exactly as
`--help` prints it, so the page can never fall behind the command line.
"""

import argparse
import os
import sys

from mkdocs.structure.files import File

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PAGE = "reference/cli.md"
WIDTH = "96"  # help text wrapped as on a 96-column terminal, the same on every machine


def _subcommands(parser):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            helps = {a.dest: a.help for a in action._choices_actions}
            for name, sub in action.choices.items():
                yield name, helps.get(name), sub


def _walk(parser, words, depth, out):
    for name, text, sub in _subcommands(parser):
        path = words + [name]
        out += ["", "#" * min(depth, 6) + " " + " ".join(path), ""]
        if text:
            out += [text[0].upper() + text[1:] + ".", ""]
        out += ["```text", sub.format_help().rstrip(), "```"]
        _walk(sub, path, depth + 1, out)


def cli_reference():
    """The Markdown of the command reference."""
    for folder in ("host", "micropython"):
        path = os.path.join(ROOT, folder)
        if path not in sys.path:
            sys.path.insert(0, path)
    saved = os.environ.get("COLUMNS")
    os.environ["COLUMNS"] = WIDTH
    try:
        from obsw_host.cli import build_parser

        parser = build_parser()
        out = [
            "# Command reference",
            "",
            "Every `obsw` command with its options, as `--help` prints them (this page is"
            " generated from the command's own parsers when the site is built). The"
            " [operator's guide](../operators-guide.md) shows them at work.",
            "",
            "```text",
            parser.format_help().rstrip(),
            "```",
        ]
        _walk(parser, ["obsw"], 2, out)
    finally:
        if saved is None:
            os.environ.pop("COLUMNS", None)
        else:
            os.environ["COLUMNS"] = saved
    return "\n".join(out) + "\n"


def on_files(files, config):
    files.append(File.generated(config, PAGE, content=cli_reference()))
    return files
