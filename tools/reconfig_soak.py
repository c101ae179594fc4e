"""Soak the CPDU arbitration: many seeds of randomly interleaved controllers, optionally with
stuck request lines, checking that both are never inside and every latch is right.

reconfig_soak.py [STEPS_PER_SEED=1000000] [SEEDS=4]   (runs on CPython or MicroPython)
"""

import sys

sys.path.insert(
    0, __file__.rsplit("/", 2)[0] + "/micropython" if "/" in __file__ else "micropython"
)

from obsw.reconfig.dekker_sim import DekkerSim  # noqa: E402


def main(argv):
    steps = int(argv[0]) if argv else 1000000
    seeds = int(argv[1]) if len(argv) > 1 else 4
    bad = 0
    for seed in range(1, seeds + 1):
        sim = DekkerSim(seed=seed)
        chunk = steps // 10
        for k in range(10):
            if k == 5:
                sim.stick(seed & 1)
            sim.run(chunk)
        c = sim.counters
        ok = c["both_inside"] == 0 and c["wrong_latch"] == 0 and c["collisions"] == 0
        bad += not ok
        print("seed %d: %s %s" % (seed, "ok" if ok else "VIOLATION", c))
    print("%d passed, %d failed" % (seeds - bad, bad))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
