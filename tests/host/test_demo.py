"""`obsw demo` runs every section to the end on this machine."""

import subprocess
import sys


def test_demo_runs_every_section():
    res = subprocess.run(
        [sys.executable, "-m", "obsw_host.cli", "demo"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert res.returncode == 0, res.stdout[-3000:] + res.stderr[-3000:]
    assert "section failed" not in res.stdout
    assert " 0 failed" in res.stdout.splitlines()[-1]
