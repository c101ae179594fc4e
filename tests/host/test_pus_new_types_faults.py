"""Random application data into every subtype of services 2, 3, 9 and 14: each TC ends in
exactly one completion or failure, no handler fails unexpectedly (``handler_errors``,
a defect, stays 0), and the provider's tables stay within their bounds."""

import asyncio
import random
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "core"))

from obsw.il.node import Node  # noqa: E402
from obsw.pus.packets import ACK_ALL  # noqa: E402
from obsw.pus.parameters import ParameterPool  # noqa: E402
from obsw.pus.services.s02_device_access import DeviceAccess  # noqa: E402
from obsw.pus.services.s03_housekeeping import Housekeeping  # noqa: E402
from obsw.pus.services.s09_time import TimeManagement  # noqa: E402
from obsw.pus.services.s14_forwarding import ForwardingControl  # noqa: E402
from pus_loop import APID, Loop, sdb  # noqa: E402


def _data(rng):
    if rng.random() < 0.5:  # small counts and IDs, so some requests get far
        return bytes(rng.choice((0, 0, 1, 1, 2, 3, 5, 9)) for _ in range(rng.randrange(0, 24)))
    return bytes(rng.randrange(256) for _ in range(rng.randrange(0, 40)))


def test_random_data_into_every_new_subtype():
    db = sdb()
    loop = Loop()
    pool = ParameterPool(db)
    hk = loop.app.register(
        Housekeeping(
            pool,
            db.housekeeping,
            max_structures=8,
            max_parameters=8,
            diagnostic=[{"sid": 1, "interval": 1, "parameters": [1]}],
        )  # fmt: skip
    )
    loop.app.register(ForwardingControl())
    loop.app.register(TimeManagement(code="cds"))
    loop.app.register(DeviceAccess(Node("obc", clock=loop.clock), timeout=0.01))
    rng = random.Random(24)
    sent = 0

    async def main():
        nonlocal sent
        for service in (2, 3, 9, 14):
            for subtype in loop.app.services[service].subtypes():
                for _ in range(150):
                    loop.ground.send(APID, service, subtype, _data(rng), None, ACK_ALL)
                    sent += 1
                    loop.pump()
                    loop.app.tick()
                    await loop.app.idle()
                    loop.pump()

    asyncio.run(main())
    # counted, not seen: service 14 requests may stop the reports from going out in real time
    c = loop.app.counters
    assert c["received"] == sent == c.get("completed", 0) + c.get("failed", 0)
    assert c.get("completed", 0) > 20 and c.get("failed", 0) > 1000
    assert loop.app.counters.get("handler_errors", 0) == 0
    assert len(hk.structures) <= 8 and len(hk.diagnostics) <= 8
    assert len(hk.functional) <= hk.max_functional
    for s in list(hk.structures.values()) + list(hk.diagnostics.values()):
        assert len(s.parameters) <= 8 and s.interval > 0
