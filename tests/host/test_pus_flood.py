"""A flood of malformed TCs of every served type into the running onboard process (every service
its database turns on, served on UDP): it stays alive, every TC ends in a service 1 report or a
counted drop, no handler fails with an exception of its own, and its memory stays flat."""

import gc
import random
import sys
import tracemalloc
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "core"))

from obsw.pus.tc import PusTc  # noqa: E402
from obsw_host.pus.ground import Ground  # noqa: E402
from obsw_host.pus.onboard import Onboard  # noqa: E402
from pus_loop import APID, sdb  # noqa: E402


def served(app):
    return sorted(
        (s, sub) for s, svc in app.services.items() for sub in range(1, 64) if svc.handler(sub)
    )


def bad_tc(rng, types):
    """A TC of a served type with junk application data, or a damaged or cut one."""
    svc, sub = rng.choice(types)
    data = bytes(rng.getrandbits(8) for _ in range(rng.randrange(24)))
    raw = PusTc(APID, svc, sub, data, rng.randrange(0x4000), source_id=3).pack()
    kind = rng.randrange(4)
    if kind == 1:  # a flipped bit
        b = bytearray(raw)
        i = rng.randrange(len(b) * 8)
        b[i // 8] ^= 1 << (i % 8)
        return bytes(b)
    if kind == 2:  # cut short
        return raw[: rng.randrange(len(raw))]
    return raw


def flood(onboard, ground, rng, types, rounds, per_round=100):
    sent = 0
    for _ in range(rounds):
        for _ in range(per_round):
            ground.sock.sendto(bad_tc(rng, types), ground.target)
            sent += 1
        assert ground.ping().ok  # a barrier, and the proof the process still answers
    return sent


def test_flood_of_malformed_tcs_into_every_service():
    onboard = Onboard(sdb(), port=0, period=0.05).start()
    rng = random.Random(17)
    try:
        types = served(onboard.app)
        assert len(types) > 50
        with Ground(sdb(), target=onboard.address[:2], timeout=5.0) as ground:
            sent = flood(onboard, ground, rng, types, 10)  # warm-up: tables reach their size
            gc.collect()
            tracemalloc.start()
            try:
                base = tracemalloc.get_traced_memory()[0]
                sent += flood(onboard, ground, rng, types, 30)
                gc.collect()
                grown = tracemalloc.get_traced_memory()[0] - base
            finally:
                tracemalloc.stop()
            counters = onboard.call(lambda: dict(onboard.app.counters))
    finally:
        onboard.stop()
    pings = 40
    assert counters["received"] == sent + pings
    assert counters.get("handler_errors", 0) == 0
    ended = counters["failed"] + counters["dropped"] + counters.get("completed", 0)
    assert ended == sent + pings, counters
    print("flood: %d TCs, counters %s, memory grown %d octets" % (sent, counters, grown))
    assert grown < 256 * 1024, grown
