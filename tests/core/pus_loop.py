"""A PUS application process and a ground user process wired back to back (test helper)."""

try:
    import asyncio
except ImportError:  # the unix port keeps asyncio frozen under ".frozen", off a custom path
    import sys

    sys.path.append(".frozen")
    import asyncio

from obsw.il.clock import SimClock
from obsw.pus.app import ApplicationProcess
from obsw.pus.sdb import loads
from obsw.pus.tm import PusTm
from obsw.pus.user import UserProcess

APID = 10

SDB = """{
  "mission": "test",
  "apids": {"pus": 10, "other": 11},
  "components": [
    {"name": "Panel",
     "attributes": [
       {"name": "angle", "parameter": 1, "type": "float32"},
       {"name": "speed", "parameter": 2, "type": "float32", "writable": true},
       {"name": "mode", "parameter": 3, "type": "uint8", "writable": true},
       {"name": "deployed", "parameter": 4, "type": "bool"},
       {"name": "label", "parameter": 5, "type": "string", "writable": true}
     ],
     "events": [
       {"name": "moved", "id": 1, "severity": "info",
        "data": [{"name": "angle", "type": "float32"}]},
       {"name": "stuck", "id": 2, "severity": "high",
        "data": [{"name": "code", "type": "uint16"}]}
     ]}
  ],
  "parameters": [{"name": "count", "id": 100, "type": "uint32"}],
  "events": [
    {"name": "low_one", "id": 3, "severity": "low"},
    {"name": "medium_one", "id": 4, "severity": "medium"},
    {"name": "pus.cycle_overrun", "id": 65281, "severity": "medium",
     "data": [{"name": "service", "type": "uint8"}]}
  ],
  "housekeeping": [{"sid": 1, "interval": 2, "parameters": [1, 2, 3], "enabled": false}]
}"""


def sdb():
    return loads(SDB)


class Loop:
    """``app`` (on-board) and ``ground`` (user process) exchanging bytes through lists."""

    def __init__(self, store=None, **app_options):
        self.clock = SimClock(1000.0)
        self.up = []  # TC bytes on their way
        self.down = []  # TM bytes on their way
        self.tm = []  # every TM sent, decoded, in order
        self.raw = []  # the same TM as bytes
        self.tc = []  # every TC sent, as bytes
        self.app = ApplicationProcess(
            APID, self.down.append, self.clock, store=store, **app_options
        )
        self.ground = UserProcess(self.up.append, self.clock, source_id=7)
        self.results = []  # (tm, decoded, transaction) in arrival order

    def pump(self):
        """Deliver everything in flight, both ways, until nothing is left."""
        while self.up or self.down:
            while self.up:
                raw = self.up.pop(0)
                self.tc.append(raw)
                self.app.receive(raw)
            while self.down:
                raw = self.down.pop(0)
                self.raw.append(raw)
                tm = PusTm.unpack(raw)
                self._declared(tm)
                self.tm.append(tm)
                r = self.ground.receive(raw)
                if r is not None:
                    self.results.append(r)

    def _declared(self, tm):
        """Every TM a standard service sends is one its provider declares in ``REPORTS``
        (what ``obsw pus coverage`` counts as served)."""
        provider = self.app.services.get(tm.service)
        if provider is None or tm.service > 23:
            return
        if (tm.service, tm.subtype) not in provider.REPORTS:
            raise AssertionError(
                "%s sent TM[%d,%d], not in its REPORTS"
                % (type(provider).__name__, tm.service, tm.subtype)
            )

    def run(self, tx):
        self.pump()
        return tx

    def run_async(self, make):
        """Run ``make()`` (returning a transaction) inside an event loop until all is done."""
        box = []

        async def main():
            box.append(make())
            for _ in range(50):
                self.pump()
                if not self.app.tasks:
                    break
                await self.app.idle()
            self.pump()

        asyncio.run(main())
        return box[0]

    def types(self):
        return [(t.service, t.subtype) for t in self.tm]

    def unsolicited(self, service, subtype):
        return [
            d
            for tm, d, tx in self.results
            if tx is None and tm.service == service and tm.subtype == subtype
        ]
