"""No silent sample: in a folder with no mission.json above it and no $OBSW_MISSION, every
command that needs a mission says so in one line and exits 2 (issue 23, through the real CLI)."""

import os
import subprocess
import sys

import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
ENV = dict(
    os.environ,
    PYTHONPATH=os.pathsep.join([os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]),
)
ENV.pop("OBSW_MISSION", None)

COMMANDS = [
    ["obc", "serve"],
    ["ground", "ping"],
    ["ground", "params", "get", "adcs.gain"],
    ["obcp", "status"],
    ["obcp", "engine", "start"],
    ["pluto", "engine"],
    ["frames", "processor", "--uart-a", "/dev/null", "--uart-b", "/dev/null"],
    ["yamcs", "config", "out"],
    ["yamcs", "run"],
    ["cfdp", "put", "a.bin"],
]


@pytest.mark.parametrize("argv", COMMANDS, ids=" ".join)
def test_a_command_with_no_mission_says_so_in_one_line(tmp_path, argv):
    empty = tmp_path / "empty"
    empty.mkdir()
    r = subprocess.run([sys.executable, "-m", "obsw_host.cli"] + argv, cwd=str(empty), env=ENV,
                       capture_output=True, text=True, timeout=30)  # fmt: skip
    assert r.returncode == 2, r.stdout + r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "no mission named" in lines[0], r.stderr
    assert "Traceback" not in r.stderr
