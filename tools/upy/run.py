"""Run core unittest files on the MicroPython unix port (which ships no unittest).

Usage: micropython run.py TEST_FILE...   prints a line per failure and 'N passed, N failed'.
"""

import sys

from obsw_run_tests import main

sys.exit(main(sys.argv[1:], collect=False))  # a large heap: see obsw_run_tests
