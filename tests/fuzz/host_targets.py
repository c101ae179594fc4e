"""Fuzz targets that exist only on CPython: the IL wire decoder."""

from fuzzcore import Target
from obsw.cbor import CborDecodeError
from obsw_host.il import wire


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
    return [
        Target("il-wire", wire.loads, [wire.dumps(m) for m in msgs], (CborDecodeError,)),
        Target(
            "il-frames",
            r.call,
            [wire.frame(m) for m in msgs],
            (wire.FrameError, CborDecodeError),
            reset=r.reset,
        ),
    ]
