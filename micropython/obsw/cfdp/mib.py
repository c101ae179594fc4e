"""CFDP management information base (727.0-B-5 8): local entity settings and, per remote
entity, transmission defaults, timer intervals and limits."""

from obsw.cfdp.defs import (
    ACKNOWLEDGED,
    FILE_CHECKSUM_FAILURE,
    HANDLER_CANCEL,
    HANDLER_IGNORE,
    UNSUPPORTED_CHECKSUM_TYPE,
)
from obsw.crc import CHECKSUM_CRC32

_MAX_REMOTES = 256  # entries made from ``default`` for the entities met so far


class RemoteEntity:
    """How this entity talks to one remote entity. Intervals in seconds; None turns a timer off.

    ``keep_alive_limit`` is the largest lag (octets) tolerated between what the sender sent and
    what the receiver reports in a Keep Alive PDU.

    ``max_file_size`` bounds what a receiving transaction accepts from this entity: file data
    or a declared size beyond it is a filestore rejection fault and is never written.
    ``max_gaps`` bounds the missing ranges a receiver tracks; beyond it the last two are
    merged (the octets between them are asked for again), so memory stays bounded.
    """

    def __init__(
        self,
        entity_id,
        *,
        mode=ACKNOWLEDGED,
        closure=False,
        crc=False,
        checksum=CHECKSUM_CRC32,
        max_segment=1024,
        max_pdu=0,
        large=False,
        eid_len=0,
        ack_interval=10.0,
        ack_limit=3,
        nak_interval=10.0,
        nak_limit=3,
        immediate_nak=True,
        inactivity=60.0,
        keep_alive_interval=None,
        keep_alive_limit=None,
        check_interval=5.0,
        check_limit=2,
        keep_incomplete=False,
        max_file_size=64 << 20,
        max_gaps=1024,
    ):
        self.entity_id = entity_id
        self.mode = mode
        self.closure = closure
        self.crc = crc
        self.checksum = checksum
        self.max_segment = max_segment
        self.max_pdu = max_pdu or max_segment + 64
        self.large = large
        self.eid_len = eid_len
        self.ack_interval = ack_interval
        self.ack_limit = ack_limit
        self.nak_interval = nak_interval
        self.nak_limit = nak_limit
        self.immediate_nak = immediate_nak
        self.inactivity = inactivity
        self.keep_alive_interval = keep_alive_interval
        self.keep_alive_limit = keep_alive_limit
        self.check_interval = check_interval
        self.check_limit = check_limit
        self.keep_incomplete = keep_incomplete
        self.max_file_size = max_file_size
        self.max_gaps = max(2, max_gaps)


class Mib:
    """The local entity: its id, default fault handlers and the remote entities it knows."""

    def __init__(
        self,
        entity_id,
        remotes=(),
        *,
        seq_len=2,
        fault_handlers=None,
        default=None,
        max_transactions=64,
    ):
        self.entity_id = entity_id
        self.max_transactions = max_transactions  # concurrent ones; more are refused, counted
        self.seq_len = seq_len
        self.remotes = {}
        for r in remotes:
            self.remotes[r.entity_id] = r
        # condition code -> handler code; anything not listed is a notice of cancellation
        self.fault_handlers = {
            FILE_CHECKSUM_FAILURE: HANDLER_CANCEL,
            UNSUPPORTED_CHECKSUM_TYPE: HANDLER_IGNORE,
        }
        if fault_handlers:
            self.fault_handlers.update(fault_handlers)
        self.default = default  # settings used for a remote entity not listed

    def remote(self, entity_id):
        r = self.remotes.get(entity_id)
        if r is None and self.default is not None and len(self.remotes) < _MAX_REMOTES:
            d = self.default
            r = RemoteEntity(entity_id)
            for k in d.__dict__:
                if k != "entity_id":
                    setattr(r, k, getattr(d, k))
            self.remotes[entity_id] = r
        return r

    def handler(self, condition, overrides=None):
        if overrides and condition in overrides:
            return overrides[condition]
        return self.fault_handlers.get(condition, HANDLER_CANCEL)
