"""pytest configuration shared by every test directory."""

import atexit
import os
import shutil
import sys
import tempfile

from hypothesis import HealthCheck, settings

# One profile for the whole suite: enough examples to find codec bugs, bounded so that
# tools/test stays within its time budget on a 2-core machine.
settings.register_profile(
    "obsw",
    max_examples=int(os.environ.get("OBSW_HYPOTHESIS_EXAMPLES", "200")),
    deadline=None,
    # CI runs the same examples every time, so a red run points at the change, not at chance;
    # developers' runs explore new examples.
    derandomize=bool(os.environ.get("CI")),
    suppress_health_check=[HealthCheck.too_slow],
)
settings.load_profile("obsw")

# The examples (demos and samples) are not part of the product; tests import them from there.
EXAMPLES = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "examples")
sys.path.insert(0, EXAMPLES)

# Per-user state (CFDP transaction sequence numbers) goes to a folder of this test run, removed
# at the end, never to the user's own state folder; subprocesses inherit it.
if "OBSW_STATE" not in os.environ:
    os.environ["OBSW_STATE"] = tempfile.mkdtemp(prefix="obsw-test-state-")
    atexit.register(shutil.rmtree, os.environ["OBSW_STATE"], True)

# The mission of every test that names none, as an operator would `export OBSW_MISSION=...`:
# the sample spacecraft, named, never a silent default of the product. Tests of what happens
# without a mission remove it (monkeypatch.delenv, or an env without it).
os.environ.setdefault("OBSW_MISSION", os.path.join(EXAMPLES, "sample"))
