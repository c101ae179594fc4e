"""Start-up: each `obsw` command imports only what it uses (the console's and the live view's
libraries, the on-board process and the storage users only for the commands that need them)."""

import json
import os
import subprocess
import sys

import pytest
from obsw_host.cli import COMMANDS

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
# imported by no command's parser: only when the command that needs them runs
HEAVY = ("prompt_toolkit", "rich", "obsw_host.pus.onboard", "obsw_host.pus.storage_ground")

PROBE = """
import json, sys
from obsw_host.cli import build_parser
build_parser(sys.argv[1])
print(json.dumps(sorted(m for m in sys.modules if m.split(".")[0] in %r or m in %r)))
""" % (tuple({h.split(".")[0] for h in HEAVY}), HEAVY)


def loaded(command):
    """The heavy modules building ``command``'s parser imports, in a fresh interpreter."""
    res = subprocess.run(
        [sys.executable, "-c", PROBE, command],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert res.returncode == 0, res.stderr
    return [m for m in json.loads(res.stdout) if m in HEAVY or m.split(".")[0] in HEAVY]


@pytest.mark.parametrize("command", ["ground", "cfdp", "packet", "mission", "obc"])
def test_a_command_parser_leaves_out_the_console_and_the_onboard_process(command):
    assert command in COMMANDS
    assert loaded(command) == []
