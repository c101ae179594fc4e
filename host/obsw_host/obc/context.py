"""The OBC's context, kept in the reconfiguration module's safeguard memory across power cycles
and switch-overs: mode, onboard time, sequence counters, the active OBCPs.

CBOR (RFC 8949) map with small integer keys, so a context fits the safeguard record's 212 bytes.
"""

from obsw import cbor

_MODE, _OBT, _UTC_AT, _SEQ, _OBCPS, _SAVES, _BOOTS = 1, 2, 3, 4, 5, 6, 7
CAPACITY = 212  # bytes a safeguard record of the OBC area holds


class ContextError(ValueError):
    """A context that does not decode, or one too large for the safeguard record."""


class ObcContext:
    """``obt``: onboard time (s, CUC epoch) at the save; ``utc_at``: ground-correlated UTC
    (s since 1958) at the same instant, so the time that passed while off can be added;
    ``seq``: {apid: next sequence count}; ``obcps``: names of the procedures running."""

    def __init__(self, mode=0, obt=0.0, utc_at=0.0, seq=None, obcps=(), saves=0, boots=0):
        self.mode = mode
        self.obt = obt
        self.utc_at = utc_at
        self.seq = dict(seq or {})
        self.obcps = list(obcps)
        self.saves = saves
        self.boots = boots

    def pack(self):
        out = cbor.dumps(
            {
                _MODE: self.mode,
                _OBT: float(self.obt),
                _UTC_AT: float(self.utc_at),
                _SEQ: self.seq,
                _OBCPS: self.obcps,
                _SAVES: self.saves,
                _BOOTS: self.boots,
            }
        )
        if len(out) > CAPACITY:
            raise ContextError("context of %d bytes, the record holds %d" % (len(out), CAPACITY))
        return out

    @classmethod
    def unpack(cls, buf):
        try:
            d = cbor.loads(bytes(buf))
        except ValueError as e:
            raise ContextError("context does not decode: %s" % e) from e
        if not isinstance(d, dict):
            raise ContextError("context is a %s, expected a map" % type(d).__name__)
        return cls(
            d.get(_MODE, 0),
            d.get(_OBT, 0.0),
            d.get(_UTC_AT, 0.0),
            d.get(_SEQ, {}),
            d.get(_OBCPS, []),
            d.get(_SAVES, 0),
            d.get(_BOOTS, 0),
        )

    def __eq__(self, other):
        return isinstance(other, ObcContext) and self.pack() == other.pack()

    def __repr__(self):
        return "ObcContext(mode=%d, obt=%.3f, seq=%r, obcps=%r, saves=%d, boots=%d)" % (
            self.mode,
            self.obt,
            self.seq,
            self.obcps,
            self.saves,
            self.boots,
        )
