#!/usr/bin/env python3
"""mpy-cross: the core as bytecode, frozen sizes, closures (``obsw_host.mpy``)."""

import sys

from obsw_host.mpy import main

if __name__ == "__main__":
    sys.exit(main(sys.argv))
