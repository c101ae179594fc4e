"""Fuzz targets that exist only on CPython: the IL wire decoder and the onboard PUS process."""

from fuzzcore import Target
from obsw.cbor import CborDecodeError
from obsw.pus.tc import PusTc
from obsw.pus.tm import PusTm
from obsw_host.il import wire


class _Capture:
    def __init__(self):
        self.sent = []

    def sendto(self, raw, addr):
        self.sent.append(raw)


class _Onboard:
    """The onboard PUS application process with every service its database turns on; each
    TC must end in a service 1 report or a counted drop, and no handler may fail with an
    exception of its own (that is a decoder raising something it does not declare)."""

    def __init__(self):
        from obsw_host.pus.onboard import Onboard
        from pus_loop import APID, sdb

        self.apid = APID
        self.onboard = Onboard(sdb(), port=0, tm_to=("ground", 1))
        self.app = self.onboard.app
        self.cap = _Capture()
        self.onboard._transport = self.cap
        self.types = sorted(
            (s, sub)
            for s, svc in self.app.services.items()
            for sub in range(1, 64)
            if svc.handler(sub)
        )

    def seeds(self):
        out = []
        for s, sub in self.types:
            for data in (b"", b"\x00\x01", b"\x00\x01\x00\x02\x00\x03\x00\x04"):
                out.append(PusTc(self.apid, s, sub, data, 1, source_id=1).pack())
        return out

    def generate(self, rng):
        s, sub = rng.pick(self.types)
        return PusTc(self.apid, s, sub, rng.bytes(rng.below(40)), rng.below(0x4000)).pack()

    def call(self, data):
        app = self.app
        cap = self.cap
        cap.sent.clear()
        dropped = app.counters.get("dropped", 0)
        errors = app.counters.get("handler_errors", 0)
        app.receive(data)
        if app.counters.get("handler_errors", 0) != errors:
            raise AssertionError("a handler failed with an exception of its own")
        if app.counters.get("dropped", 0) == dropped:
            kinds = [PusTm.unpack(raw).message_type for raw in cap.sent]
            if not [k for k in kinds if k[0] == 1]:
                raise AssertionError("TC neither reported nor counted: %r" % (kinds,))


class _Reader:
    def __init__(self):
        self.reset()

    def reset(self):
        self.reader = wire.FrameReader()

    def call(self, data):
        self.reader.feed(data)


def targets():
    msgs = [{"op": "call", 1: b"\x00\x01", "args": [1, 2.5, None]}, [1, {2: [3]}], "x" * 40]
    r = _Reader()
    ob = _Onboard()
    return [
        Target("pus-onboard", ob.call, ob.seeds(), (), ob.generate),
        Target("il-wire", wire.loads, [wire.dumps(m) for m in msgs], (CborDecodeError,)),
        Target(
            "il-frames",
            r.call,
            [wire.frame(m) for m in msgs],
            (wire.FrameError, CborDecodeError),
            reset=r.reset,
        ),
    ]
