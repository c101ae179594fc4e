"""Random application data into every request of services 6, 15, 21 and 22: each gets its
verification reports and nothing reaches the process as a handler defect."""

import random
import unittest

from obsw.cfdp.filestore import MemoryFilestore
from obsw.pus.parameters import ParameterPool
from obsw.pus.sdb import loads
from obsw.pus.services.s06_memory import BytesMemory, MemoryManagement
from obsw.pus.services.s15_storage import Storage
from obsw.pus.services.s21_sequencing import RequestSequencing
from obsw.pus.services.s22_position_scheduling import PositionScheduling
from obsw.pus.services.s23_files import FileManagement
from obsw.pus.tc import PusTc
from pus_loop import APID, Loop

SDB = """{"apids": {"pus": 10},
  "parameters": [{"name": "orbit", "id": 100, "type": "uint32", "writable": true}]}"""

# (data that decodes for each subtype, so random changes of it reach deep into the handler)
SEEDS = {
    (6, 1): b"\x00\x01\x00\x00\x01\x00\x00\x00\x02\x00\x02PQ\x00\x00",
    (6, 11): b"\x00\x01\x00\x00\x10\x00\x00\x02PQ\x00\x00",
    (6, 12): b"",
    (6, 13): b"\x00\x01",
    (6, 14): b"\x00\x01",
    (6, 15): b"\x00\x01",
    (6, 16): b"\x00\x01",
    (6, 17): b"\x00\x01\x00\x00",
    (6, 19): b"\x00\x01\x01\x00\x00\x10\x00\x00\x03SAT\x00\x05p.bin\x00\x00",
    (6, 20): b"\x00\x01\x01\x00\x00\x10\x00\x00\x00\x00\x08\x00\x03SAT\x00\x05d.bin",
    (6, 21): b"\x00\x01\x00\x00\x01\x00\x00\x00\x00\x00\x03SAT\x00\x05p.bin\x00\x00",
    (6, 22): b"\x00\x01\x00\x00\x01\x00\x00\x00\x00\x00\x00\x00\x08\x00\x03SAT\x00\x05d.bin",
    (15, 24): b"\x00" + bytes(12) + b"\x00\x01\x00\x02",
    (15, 31): b"\x00\x01\x01\x00\x0a\x01\x00\x05",
    (15, 32): b"\x00\x01\x01\x00\x0a\x01\x00\x05",
    (15, 37): b"\x00\x01",
    (21, 2): b"\x01s\x00\x03SAT\x00\x05w.seq",
    (21, 8): b"\x01s\x00\x03SAT\x00\x05w.seq",
    (22, 28): b"\x00\x00\x00\x05",
}


def mutate(rng, data):
    d = bytearray(data)
    for _ in range(rng.randint(0, 3)):
        what = rng.randint(0, 2)
        if what == 0 and d:
            d[rng.randint(0, len(d) - 1)] = rng.randint(0, 255)
        elif what == 1 and d:
            d = d[: rng.randint(0, len(d) - 1)]  # cut short
        else:
            d.append(rng.randint(0, 255))
    return bytes(d)


class TestRobust(unittest.TestCase):
    def test_random_requests(self):
        fs = MemoryFilestore({"p.bin": b"PQ", "w.seq": b"\x00\x00"})
        loop = Loop()
        app = loop.app
        pool = ParameterPool(loads(SDB))
        app.register(MemoryManagement({1: BytesMemory(64, 0x1000, True, None, {1: ("t", 8, 8)})}))
        app.register(FileManagement(fs))
        app.register(Storage((), MemoryFilestore()))
        app.register(RequestSequencing())
        app.register(PositionScheduling(pool, "orbit"))
        rng = random.Random(2026) if hasattr(random, "Random") else None
        if rng is None:  # MicroPython's random is the module itself
            random.seed(2026)
            rng = random
        seq = 0
        for (service, subtype), data in sorted(SEEDS.items()):
            for _ in range(40):
                seq = (seq + 1) & 0x3FFF
                raw = PusTc(APID, service, subtype, mutate(rng, data), seq, source_id=7).pack()
                before = len(loop.down)
                app.receive(raw)
                app.tick()
                self.assertTrue(len(loop.down) > before, (service, subtype))
                loop.down.clear()
        self.assertEqual(app.counters.get("handler_errors", 0), 0)
        self.assertEqual(app.counters.get("cyclic_errors", 0), 0)


if __name__ == "__main__":
    unittest.main()
