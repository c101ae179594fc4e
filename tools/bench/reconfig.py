"""Benchmark of the reconfiguration module's core: CPDU arbitration steps and safeguard memory
records per second, each next to a plain reference doing the same I/O without the logic
(scheduler alone; raw EEPROM page writes/reads; CRC-32 alone, C-accelerated on CPython).

reconfig.py [--quick] [--json]
"""

import json
import os
import statistics
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "micropython"))

from obsw.crc import crc32  # noqa: E402
from obsw.reconfig import ecc  # noqa: E402
from obsw.reconfig.dekker_sim import DekkerSim, Rng  # noqa: E402
from obsw.reconfig.eeprom import M24512  # noqa: E402
from obsw.reconfig.models import M24512Model, SimI2C  # noqa: E402
from obsw.reconfig.safeguard import Safeguard  # noqa: E402


def rate(fn, n, runs):
    out = []
    for _ in range(runs):
        t = time.perf_counter()
        fn(n)
        out.append(n / (time.perf_counter() - t))
    return statistics.median(out)


def dekker(n):
    DekkerSim(seed=3).run(n)


def scheduler_only(n):
    # the reference: the same seeded scheduling and clock, no controllers or lines
    rng = Rng(3)
    now = 0
    picks = [0, 0]
    for _ in range(n):
        now += rng.below(41)
        picks[rng.next() & 1] += 1


def devices():
    i2c = SimI2C()
    for a in (0x50, 0x51):
        i2c.devices[a] = M24512Model(busy_polls=0)
    return [M24512(i2c, 0x50), M24512(i2c, 0x51)]


PAYLOAD = bytes(range(64))


def sg_write(n):
    sg = Safeguard(devices(), records=8)
    for i in range(n):
        sg.write(i & 7, PAYLOAD)


def raw_write(n):
    devs = devices()
    for i in range(n):
        for d in devs:
            d.write((i & 7) * 256, PAYLOAD)


def sg_read(n):
    sg = Safeguard(devices(), records=8)
    for k in range(8):
        sg.write(k, PAYLOAD)
    for i in range(n):
        sg.read(i & 7)


def raw_read(n):
    devs = devices()
    for i in range(n):
        for d in devs:
            for slot in (0, 1):
                d.read((i & 7) * 256 + slot * 128, 126)


def ecc_encode(n):
    block = bytes(112)
    for _ in range(n):
        ecc.encode(block)


def crc_only(n):
    block = bytes(112)
    for _ in range(n):
        crc32(block)


CASES = (
    ("arbitration (both controllers)", "steps/s", dekker, scheduler_only, 100000),
    ("safeguard record write (2 EEPROMs, verified)", "records/s", sg_write, raw_write, 400),
    ("safeguard record read (4 copies, checked)", "records/s", sg_read, raw_read, 400),
    ("SECDED encode of a 112-byte slot", "slots/s", ecc_encode, crc_only, 2000),
)


def main(argv):
    quick = "--quick" in argv
    runs = 3 if quick else 7
    rows = []
    for case, unit, ours, ref, n in CASES:
        n = n // 4 if quick else n
        rows.append((case, unit, rate(ours, n, runs), rate(ref, n, runs)))
    if "--json" in argv:
        out = []
        for case, unit, a, b in rows:
            out.append(
                {"case": case, "impl": "obsw", "value": a, "unit": unit, "higher_is_better": True}
            )
            out.append(
                {
                    "case": case,
                    "impl": "reference",
                    "value": b,
                    "unit": unit,
                    "higher_is_better": True,
                }
            )
        print(json.dumps({"bench": "reconfig", "rows": out}))
        return 0
    print("%-46s %14s %14s %7s" % ("case", "obsw", "reference", "ratio"))
    for case, unit, a, b in rows:
        print("%-46s %14.0f %14.0f %7.2f  %s" % (case, a, b, a / b, unit))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
