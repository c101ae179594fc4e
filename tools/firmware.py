#!/usr/bin/env python3
"""MicroPython images from the pinned source and the QEMU board (``obsw_host.firmware``)."""

import sys

from obsw_host.firmware import main

if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
