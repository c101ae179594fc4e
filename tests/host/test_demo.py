"""The demo (examples/demo.py, what tools/demo runs) runs every section to the end on this
machine and leaves nothing behind in the temporary folder."""

import os
import pathlib
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_demo_runs_every_section_and_leaves_no_temporary_files():
    with tempfile.TemporaryDirectory(prefix="obsw-demo-tmp-") as tmp:
        # the demo's system temp folder is this empty one, so what it leaves is visible
        env = dict(os.environ, TMPDIR=tmp)
        res = subprocess.run(
            [sys.executable, str(ROOT / "examples" / "demo.py")],
            capture_output=True,
            text=True,
            timeout=900,  # a guard against a hung section, not a time limit
            env=env,
        )
        left = sorted(os.listdir(tmp))
    assert res.returncode == 0, res.stdout[-3000:] + res.stderr[-3000:]
    assert "section failed" not in res.stdout
    assert " 0 failed" in res.stdout.splitlines()[-1]
    assert left == []
