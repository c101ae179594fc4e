"""A flood of malformed TCs of every served type into the running onboard process (every service
on, served on UDP): it stays alive, every TC ends in a service 1 report or a counted drop, no
handler fails with an exception of its own, and its memory stays flat. Once against the PUS
process alone, once against the OBC's core process (PUS services 1-23, CFDP, OBCP engine)."""

import gc
import json
import logging
import os
import random
import sys
import tracemalloc
from pathlib import Path

import pytest
from mission_ports import free_port

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "core"))

from obsw.pus.tc import PusTc  # noqa: E402
from obsw_host.pus.ground import Ground  # noqa: E402
from obsw_host.pus.onboard import Onboard  # noqa: E402
from pus_loop import APID, sdb  # noqa: E402


@pytest.fixture(autouse=True)
def quiet_onboard_log():
    """The onboard log writes a line per TC, and pytest keeps every record it captures: that
    would be the test runner's memory growing, not the process's. Warnings still show."""
    log = logging.getLogger("obsw.onboard")
    level = log.level
    log.setLevel(logging.WARNING)
    yield
    log.setLevel(level)


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


def measure(onboard, db, target, seed):
    """Flood, then the figures: TCs sent, the counters, traced memory growth (octets)."""
    rng = random.Random(seed)
    types = served(onboard.app)
    with Ground(db, target=target, timeout=5.0) as ground:
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
    return types, sent, counters, grown


def check(types, sent, counters, grown):
    pings = 40
    print("flood: %d TCs of %d types, counters %s, memory grown %d octets"
          % (sent, len(types), counters, grown))  # fmt: skip
    assert counters["received"] == sent + pings
    assert counters.get("handler_errors", 0) == 0
    ended = counters["failed"] + counters["dropped"] + counters.get("completed", 0)
    assert ended == sent + pings, counters
    assert grown < 256 * 1024, grown


def test_flood_into_the_obc_core_process(tmp_path):
    from obsw_host.mission import config as obc_config
    from obsw_host.obc.assembly import ObcProcess
    from obsw_host.sample import MISSION_DIR, MISSION_PATH

    with open(MISSION_PATH) as f:
        doc = json.load(f)
    base = MISSION_DIR
    doc["sdb"] = os.path.join(base, doc["sdb"])
    if "obcp" in doc:
        doc["obcp"]["files"] = os.path.join(base, doc["obcp"]["files"])
    doc["processes"] = {"core": ["pus", "cfdp", "obcp"]}
    doc["pus"]["port"] = port = free_port()
    doc["cfdp"]["port"] = free_port()
    doc["state"] = str(tmp_path / "state")
    path = tmp_path / "mission.json"
    path.write_text(json.dumps(doc))
    config = obc_config.load(str(path))
    proc = ObcProcess(config, "core", out=lambda *a: None).start()
    try:
        onboard = proc.unit("pus").onboard
        figures = measure(onboard, proc.sdb, ("127.0.0.1", port), 18)
    finally:
        proc.stop()
    assert len(figures[0]) > 80
    check(*figures)


def test_flood_of_malformed_tcs_into_every_service():
    onboard = Onboard(sdb(), port=0, period=0.05).start()
    try:
        figures = measure(onboard, sdb(), onboard.address[:2], 17)
    finally:
        onboard.stop()
    assert len(figures[0]) > 50
    check(*figures)
