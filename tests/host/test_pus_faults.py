"""Thousands of malformed TCs into a running application process: each one gets a failure
report or a counted drop, the process keeps serving, and its memory stays flat."""

import gc
import random
import sys
import tracemalloc
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "core"))

from obsw.il.clock import SimClock  # noqa: E402
from obsw.pus.app import ApplicationProcess  # noqa: E402
from obsw.pus.events import EventManager  # noqa: E402
from obsw.pus.parameters import ParameterPool  # noqa: E402
from obsw.pus.services.s03_housekeeping import Housekeeping  # noqa: E402
from obsw.pus.services.s05_events import EventReporting  # noqa: E402
from obsw.pus.services.s09_time import TimeManagement  # noqa: E402
from obsw.pus.services.s17_test import ServiceTest  # noqa: E402
from obsw.pus.services.s20_parameters import ParameterManagement  # noqa: E402
from obsw.pus.tc import PusTc  # noqa: E402
from obsw.pus.tm import PusTm  # noqa: E402
from obsw_host.pus.ground import Ground  # noqa: E402
from obsw_host.pus.onboard import Onboard  # noqa: E402
from pus_loop import APID, sdb  # noqa: E402

# TCs whose application data no subtype can take, and types nobody serves
_BAD_DATA = [
    (17, 1, b"\x00"),
    (17, 3, b"\x00"),
    (17, 3, b"\x00\x0a\x00"),
    (3, 27, b"\x00\x05\x00\x01"),  # N = 5, one SID
    (3, 1, b"\x00\x09"),
    (3, 31, b"\x00\x01\x00"),
    (5, 5, b"\x03\x00\x01"),
    (5, 7, b"\x00"),
    (9, 1, b""),
    (9, 1, b"\x01\x02"),
    (20, 1, b"\x04\x00\x01"),
    (20, 1, b""),
    (3, 9, b"\x00\x01\x00\x63"),  # unknown SID: start failure
    (20, 1, b"\x01\x03\xe7"),  # unknown parameter: start failure
    (5, 6, b"\x01\x03\xe7"),  # unknown event: start failure
]


def valid_tc(rng):
    return PusTc(APID, 17, 1, b"", rng.randrange(0x4000), source_id=1).pack()


def malformed(rng):
    """A TC no process may accept: a damaged valid one, noise, or a bad request."""
    kind = rng.randrange(6)
    if kind == 0:  # one flipped bit: the CRC (or a header check) catches it
        raw = bytearray(valid_tc(rng))
        i = rng.randrange(len(raw) * 8)
        raw[i // 8] ^= 1 << (i % 8)
        return bytes(raw)
    if kind == 1:  # cut short
        raw = valid_tc(rng)
        return raw[: rng.randrange(len(raw))]
    if kind == 2:  # noise
        return bytes(rng.getrandbits(8) for _ in range(rng.randrange(40)))
    if kind == 3:  # bytes after a valid packet
        return valid_tc(rng) + bytes(rng.randrange(1, 9))
    if kind == 4:  # a type nobody serves
        if rng.randrange(2):
            svc, sub = rng.choice((2, 4, 6, 8, 11, 99, 200, 255)), rng.randrange(256)
        else:
            svc, sub = rng.choice((3, 5, 9, 17, 20)), rng.randrange(45, 256)
        return PusTc(APID, svc, sub, b"", rng.randrange(0x4000)).pack()
    svc, sub, data = rng.choice(_BAD_DATA)
    return PusTc(APID, svc, sub, data, rng.randrange(0x4000)).pack()


def build():
    db = sdb()
    out = []
    app = ApplicationProcess(APID, out.append, SimClock(1000.0), period=0.1)
    pool = ParameterPool(db)
    app.register(Housekeeping(pool, db.housekeeping))
    app.register(EventReporting(known=db.events))
    app.register(TimeManagement(0))
    app.register(ServiceTest())
    app.register(ParameterManagement(pool))
    EventManager(db).connect(app)
    return app, out


def feed(app, out, rng, count):
    failures = drops = 0
    for _ in range(count):
        out.clear()
        dropped = app.counters.get("dropped", 0)
        app.receive(malformed(rng))
        kinds = [PusTm.unpack(raw).message_type for raw in out]
        if app.counters.get("dropped", 0) == dropped + 1:
            assert kinds == []
            drops += 1
        else:
            assert kinds[-1] in ((1, 2), (1, 4)), kinds
            assert (1, 7) not in kinds
            failures += 1
        if rng.randrange(50) == 0:
            app.clock.advance(0.1)
            app.tick()  # the process keeps cycling meanwhile
    return failures, drops


def test_thousands_of_malformed_tcs():
    app, out = build()
    rng = random.Random(4)
    failures, drops = feed(app, out, rng, 5000)
    assert failures + drops == 5000
    assert failures > 3000 and drops > 100
    assert app.counters["failed"] + app.counters["dropped"] == 5000
    assert set(app.failures) >= {1, 2, 3, 4, 5, 6, 9}
    out.clear()
    app.receive(valid_tc(rng))
    assert [PusTm.unpack(r).message_type for r in out] == [(1, 1), (1, 3), (17, 2), (1, 7)]


def test_memory_stays_flat():
    app, out = build()
    rng = random.Random(5)
    feed(app, out, rng, 3000)  # warm up: every table and cache reaches its size
    gc.collect()
    tracemalloc.start()
    try:
        before = tracemalloc.take_snapshot()
        base = tracemalloc.get_traced_memory()[0]
        feed(app, out, rng, 5000)
        out.clear()
        gc.collect()
        grown = tracemalloc.get_traced_memory()[0] - base
        after = tracemalloc.take_snapshot()
    finally:
        tracemalloc.stop()
    top = after.compare_to(before, "lineno")[:5]
    assert grown < 64 * 1024, (grown, top)


def test_malformed_datagrams_into_the_udp_process():
    db_module = sdb()
    onboard = Onboard(db_module, port=0, period=0.05).start()
    rng = random.Random(6)
    try:
        with Ground(db_module, target=onboard.address[:2], timeout=5.0) as ground:
            sent = 0
            for _ in range(20):
                for _ in range(100):
                    ground.sock.sendto(malformed(rng), ground.target)
                    sent += 1
                assert ground.ping().ok  # a barrier: everything before it was handled
            counters = onboard.call(lambda: dict(onboard.app.counters))
            assert counters["received"] == sent + 20
            assert counters["failed"] + counters["dropped"] == sent
            assert counters["completed"] == 20
    finally:
        onboard.stop()
