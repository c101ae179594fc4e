# The QEMU Cortex-M board image: the whole core, the board's boot
# script, the board-side test runner and heap session, and the core tests with their support
# modules (all frozen: their code takes no heap, as on a board whose image carries its tests).
metadata(version="0.1.0", description="obsw core and tests on the QEMU Cortex-M board")

add_library("obsw", "lib")
require("obsw", library="obsw")  # the core, as core.py freezes it
# asyncio as a Pyboard has it (the qemu port builds without it): the package with its pure-Python
# task queue in place of the C one
package(
    "asyncio",
    ("__init__.py", "core.py", "event.py", "funcs.py", "lock.py", "stream.py", "task.py"),
    base_path="$(MPY_DIR)/extmod",
    opt=3,
)
module("_boot.py", base_path="../boards/OBSW_QEMU")
module("unittest.py", base_path="../tools/upy")
module("obsw_run_tests.py", base_path="../tools/upy")
module("obsw_heap.py", base_path="../tools/upy")
freeze("../build/fw/board-tests")  # tests/core/*.py that freeze (tools/firmware.py)
