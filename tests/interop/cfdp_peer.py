"""cfdp-py (PyPI) wrapped to look like our CfdpEntity to the simulated link: the interop oracle.

Its timers read ``spacepackets.countdown.time_ms``; ``use_sim_clock`` points that at the link's
simulated clock so no test waits in real time.
"""

from pathlib import Path

import spacepackets.countdown as countdown
from cfdppy import (
    CfdpUserBase,
    IndicationConfig,
    LocalEntityConfig,
    PutRequest,
    RemoteEntityConfig,
    RemoteEntityConfigTable,
)
from cfdppy.handler.dest import DestHandler
from cfdppy.handler.source import SourceHandler
from cfdppy.handler.source import TransactionStep as SourceStep
from cfdppy.mib import CheckTimerProvider, DefaultFaultHandlerBase
from spacepackets.cfdp import ChecksumType, TransmissionMode
from spacepackets.cfdp.pdu import PduFactory
from spacepackets.countdown import Countdown
from spacepackets.seqcount import SeqCountProvider
from spacepackets.util import ByteFieldU8


def use_sim_clock(monkeypatch, link):
    monkeypatch.setattr(countdown, "time_ms", lambda: round(link.now * 1000))


class _User(CfdpUserBase):
    def __init__(self):
        super().__init__()
        self.events = []
        self.finished = []

    def transaction_indication(self, params):
        self.events.append(("transaction", params))

    def eof_sent_indication(self, transaction_id):
        self.events.append(("eof_sent", transaction_id))

    def transaction_finished_indication(self, params):
        self.finished.append(params.finished_params)

    def metadata_recv_indication(self, params):
        self.events.append(("metadata", params))

    def file_segment_recv_indication(self, params):
        pass

    def report_indication(self, transaction_id, status_report):
        self.events.append(("report", transaction_id))

    def suspended_indication(self, transaction_id, cond_code):
        self.events.append(("suspended", cond_code))

    def resumed_indication(self, transaction_id, progress):
        self.events.append(("resumed", progress))

    def fault_indication(self, transaction_id, cond_code, progress):
        self.events.append(("fault", cond_code))

    def abandoned_indication(self, transaction_id, cond_code, progress):
        self.events.append(("abandoned", cond_code))

    def eof_recv_indication(self, transaction_id):
        self.events.append(("eof_recv", transaction_id))


class _Faults(DefaultFaultHandlerBase):
    def __init__(self):
        super().__init__()
        self.faults = []

    def notice_of_suspension_cb(self, transaction_id, cond, progress):
        self.faults.append(("suspend", cond))

    def notice_of_cancellation_cb(self, transaction_id, cond, progress):
        self.faults.append(("cancel", cond))

    def abandoned_cb(self, transaction_id, cond, progress):
        self.faults.append(("abandon", cond))

    def ignore_cb(self, transaction_id, cond, progress):
        self.faults.append(("ignore", cond))


class _CheckTimers(CheckTimerProvider):
    def __init__(self, seconds):
        self.seconds = seconds

    def provide_check_timer(self, local_entity_id, remote_entity_id, entity_type):
        return Countdown.from_seconds(self.seconds)


_BUSY_STEPS = (
    SourceStep.TRANSACTION_START,
    SourceStep.SENDING_METADATA,
    SourceStep.SENDING_FILE_DATA,
    SourceStep.RETRANSMITTING,
    SourceStep.SENDING_EOF,
)


class PeerEntity:
    """A cfdp-py source handler and destination handler behind the CfdpEntity link interface."""

    def __init__(
        self,
        local_id,
        remote_id,
        *,
        mode=TransmissionMode.ACKNOWLEDGED,
        checksum=ChecksumType.CRC_32,
        segment=64,
        closure=True,
        timer=2.0,
        limit=10,
    ):
        self.user = _User()
        self.faults = _Faults()
        cfg = LocalEntityConfig(ByteFieldU8(local_id), IndicationConfig(), self.faults)
        remote = RemoteEntityConfig(
            entity_id=ByteFieldU8(remote_id),
            max_file_segment_len=segment,
            max_packet_len=segment + 64,
            closure_requested=closure,
            crc_on_transmission=False,
            default_transmission_mode=mode,
            crc_type=checksum,
            positive_ack_timer_interval_seconds=timer,
            positive_ack_timer_expiration_limit=limit,
            nak_timer_interval_seconds=timer,
            nak_timer_expiration_limit=limit,
            check_limit=limit,
        )
        table = RemoteEntityConfigTable([remote])
        timers = _CheckTimers(timer)
        self.source = SourceHandler(cfg, self.user, table, timers, SeqCountProvider(16))
        self.dest = DestHandler(cfg, self.user, table, timers)
        self.remote_id = remote_id
        self.mode = mode
        self.outbox = []
        self.now = 0.0
        self.ignored = 0
        self.received = 0

    def put(self, source, dest, mode=None, closure=None):
        req = PutRequest(
            destination_id=ByteFieldU8(self.remote_id),
            source_file=Path(source),
            dest_file=Path(dest),
            trans_mode=self.mode if mode is None else mode,
            closure_requested=closure,
        )
        self.source.put_request(req)

    def _drain(self, h):
        while h.packets_ready:
            self.outbox.append((self.remote_id, h.get_next_packet().pack()))

    def receive(self, raw, now):
        self.now = now
        self.received += 1
        try:
            pdu = PduFactory.from_raw(raw)
        except Exception:
            self.ignored += 1
            return
        from cfdppy import PacketDestination, get_packet_destination

        h = (
            self.source
            if get_packet_destination(pdu) == PacketDestination.SOURCE_HANDLER
            else self.dest
        )
        self._drain(h)
        try:
            h.state_machine(pdu)
        except Exception:
            # the peer refuses PDUs it does not expect in its state (by raising); count them
            self.ignored += 1
        self._drain(h)

    def transmit(self, now, limit=32):
        self.now = now
        for h in (self.source, self.dest):
            for _ in range(limit):
                self._drain(h)
                if h.state.name == "IDLE":
                    break
                try:
                    h.state_machine()
                except Exception:
                    self.ignored += 1
                    break
                if not h.packets_ready:
                    break
            self._drain(h)
        out = self.outbox
        self.outbox = []
        return out

    def poll(self, now):
        self.now = now

    def pending(self):
        return bool(self.outbox) or (
            self.source.state.name != "IDLE" and self.source.step in _BUSY_STEPS
        )

    def next_deadline(self):
        if self.source.state.name != "IDLE" or self.dest.state.name != "IDLE":
            return self.now + 0.25
        return None

    def pop_indications(self):
        return []
