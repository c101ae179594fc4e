"""The whole reconfiguration application in a MicroPython unix-port process for a long
simulated run (24000 loop passes, an HPC every 2000): its heap stays flat and within 64 KiB.

The unix port keeps imported bytecode on the heap (a board keeps it frozen in flash), so the
process gets room for the bytecode and the EEPROM models; what is measured is the heap the
application itself holds, after gc, from its creation on."""

import os
import subprocess

import pytest
from obsw_sim.reconfig import compile_controller, micropython_binary, mpy_cross_binary

HERE = os.path.dirname(os.path.abspath(__file__))

pytestmark = pytest.mark.skipif(
    micropython_binary() is None or mpy_cross_binary() is None,
    reason="needs the MicroPython unix port and mpy-cross",
)


def test_heap_flat_over_a_long_run(tmp_path):
    assert compile_controller(str(tmp_path))
    env = dict(os.environ, MICROPYPATH=str(tmp_path))
    r = subprocess.run(
        [micropython_binary(), "-X", "heapsize=1M", os.path.join(HERE, "reconfig_heap_run.py")]
        + ["12"],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stdout + r.stderr
    used = [int(line.split()[2]) for line in r.stdout.splitlines() if line.startswith("heap")]
    assert len(used) == 12
    assert max(used) < 64 * 1024
    assert max(used[2:]) - min(used[2:]) <= 512  # flat after warm-up
    assert "errors 0" in r.stdout
    assert "hpcs 12" in r.stdout
