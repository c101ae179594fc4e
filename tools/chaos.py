#!/usr/bin/env python3
"""The chaos campaign (``obsw_sim.chaos``): the whole chain under random faults for a while,
what was lost counted. ``python tools/chaos.py --minutes 30 --seed 7 --json figures.json``."""

import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]

from obsw_sim.chaos import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main())
