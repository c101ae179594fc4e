# The QEMU Cortex-M board image: the whole core (core.py gives the metadata), the board's boot
# script, and the board-side test runner and heap session (frozen: their code takes no heap).
include("core.py")
module("_boot.py", base_path="../boards/OBSW_QEMU")
module("unittest.py", base_path="../tools/upy")
module("obsw_run_tests.py", base_path="../tools/upy")
module("obsw_heap.py", base_path="../tools/upy")
