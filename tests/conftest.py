"""pytest configuration shared by every test directory."""

import atexit
import os
import shutil
import sys
import tempfile

from hypothesis import HealthCheck, settings


def _own_loopback():
    """Under pytest-xdist (``tools/test`` runs the suite in parallel), each worker takes a
    network namespace of its own with only a loopback, when it may (root): the tests that run
    the sample on its default ports, as a reader of the docs would, never meet each other nor an
    OBC or Yamcs already running on this machine. Subprocesses inherit it."""
    if os.environ.get("PYTEST_XDIST_WORKER") is None or os.geteuid() != 0:
        return False
    import ctypes
    import subprocess

    ip = shutil.which("ip") or next(
        (p for p in ("/usr/sbin/ip", "/sbin/ip") if os.path.exists(p)), None
    )
    libc = ctypes.CDLL(None, use_errno=True)
    if ip is None or libc.unshare(0x40000000) != 0:  # CLONE_NEWNET
        return False
    # the loopback up, with multicast (the simulated SpaceCAN buses are UDP multicast groups)
    subprocess.run([ip, "link", "set", "lo", "up", "multicast", "on"], check=True)
    subprocess.run([ip, "route", "add", "224.0.0.0/4", "dev", "lo"], check=True)
    return True


OWN_LOOPBACK = _own_loopback()

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
if os.environ.get("PYTEST_XDIST_WORKER"):  # each worker its own (an OBC locks its state folder)
    os.environ["OBSW_STATE"] = os.path.join(
        os.environ["OBSW_STATE"], os.environ["PYTEST_XDIST_WORKER"]
    )
    os.makedirs(os.environ["OBSW_STATE"], exist_ok=True)

# The mission of every test that names none, as an operator would `export OBSW_MISSION=...`:
# the sample spacecraft, named, never a silent default of the product. Tests of what happens
# without a mission remove it (monkeypatch.delenv, or an env without it).
os.environ.setdefault("OBSW_MISSION", os.path.join(EXAMPLES, "sample"))
