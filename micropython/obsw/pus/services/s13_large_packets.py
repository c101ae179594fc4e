"""ST[13] large packet transfer: messages too large for one packet, in parts, both ways.

Downlink: ``downlink(message)`` splits a message (typically a whole TM packet larger than the
link takes) into TM[13,1] first, TM[13,2] intermediate and TM[13,3] last parts, sent
``parts_per_cycle`` per application process cycle; ``abort_downlink`` stops one. Uplink:
TC[13,9], [13,10] and [13,11] parts are put back together in sequence; a part out of
sequence, a message above ``max_size``, or no part for ``timeout`` seconds aborts the
reception with a TM[13,16] uplink abortion report. At most ``max_receptions`` receptions
are in progress at once (so at most that many times ``max_size`` octets are held); a first
part beyond them is refused (service 1 failure, nothing kept). A complete message is handed to
``deliver`` (default: the application process, as the TC packet it holds).

Each part carries the large message transaction ID, the part sequence number (the first part
is 1) and the part as an octet string (ECSS-E-ST-70-41C 6.13).
"""

from obsw.compat import const
from obsw.pus.fields import field
from obsw.pus.messages import (
    FAILURE_REFUSED,
    SERVICE_LARGE_PACKET_TRANSFER,
    TC_LARGE_UPLINK_FIRST,
    TC_LARGE_UPLINK_INTERMEDIATE,
    TC_LARGE_UPLINK_LAST,
    TM_LARGE_DOWNLINK_FIRST,
    TM_LARGE_DOWNLINK_INTERMEDIATE,
    TM_LARGE_DOWNLINK_LAST,
    TM_LARGE_UPLINK_ABORTION,
)
from obsw.pus.services.base import E8, U16, Service, ServiceUser
from obsw.pus.services.s01_verification import PusFailure
from obsw.pus.structure import Structure
from obsw.pus.tm import PusTm

TRANSACTION_ID = U16
PART_NUMBER = U16
PART = Structure([("tid", TRANSACTION_ID), ("seq", PART_NUMBER), ("part", field(7, 0))])
ABORTION = Structure([("tid", TRANSACTION_ID), ("reason", E8)])

# reasons in an uplink abortion report (mission-defined values)
ABORT_TIMEOUT = const(1)  # no part within the reception timeout
ABORT_SEQUENCE = const(2)  # a part out of sequence, or no first part
ABORT_TOO_LARGE = const(3)  # the message outgrew the largest one accepted
ABORT_UNDELIVERABLE = const(4)  # the complete message was refused by its receiver
ABORT_COMMANDED = const(5)  # aborted on request
REASON_NAMES = {
    ABORT_TIMEOUT: "reception timeout",
    ABORT_SEQUENCE: "part out of sequence",
    ABORT_TOO_LARGE: "message too large",
    ABORT_UNDELIVERABLE: "undeliverable",
    ABORT_COMMANDED: "aborted",
}


def split(message, part_size):
    """The parts of ``message`` (at least two: a first and a last)."""
    if part_size < 1:
        raise ValueError("part size must be >= 1 octet, got %r" % (part_size,))
    n = len(message)
    size = part_size if n > part_size else max(1, (n + 1) // 2)
    parts = [message[i : i + size] for i in range(0, n, size)]
    while len(parts) < 2:
        parts.append(b"")
    return parts


MAX_RECEPTIONS = const(4)  # uplink receptions in progress at once (docs/hardening.md)


class _Reception:
    __slots__ = ("tid", "seq", "parts", "size", "last", "source")

    def __init__(self, tid, now, source):
        self.tid = tid
        self.seq = 0
        self.parts = []
        self.size = 0
        self.last = now
        self.source = source


class LargePacketTransfer(Service):
    """The service 13 provider (see the module text)."""

    SERVICE = SERVICE_LARGE_PACKET_TRANSFER
    REPORTS = (
        TM_LARGE_DOWNLINK_FIRST,
        TM_LARGE_DOWNLINK_INTERMEDIATE,
        TM_LARGE_DOWNLINK_LAST,
        TM_LARGE_UPLINK_ABORTION,
    )
    HANDLERS = (
        (TC_LARGE_UPLINK_FIRST, "first"),
        (TC_LARGE_UPLINK_INTERMEDIATE, "intermediate"),
        (TC_LARGE_UPLINK_LAST, "last"),
    )

    def __init__(
        self,
        part_size=256,
        timeout=10.0,
        max_size=65542,
        parts_per_cycle=8,
        deliver=None,
        max_receptions=MAX_RECEPTIONS,
    ):
        super().__init__()
        self.max_receptions = max_receptions
        self.refused = 0
        self.part_size = part_size
        self.timeout = timeout
        self.max_size = max_size
        self.parts_per_cycle = parts_per_cycle
        self.deliver = deliver
        self.receptions = {}  # tid -> _Reception
        self.outgoing = []  # [tid, [parts], next index, destination]
        self.next_tid = 1
        self.delivered = 0
        self.aborted = 0

    # -------------------------------------------------------------------------- uplink

    def _now(self):
        return self.app.clock.now()

    def _abort(self, tid, reason, destination=0):
        self.receptions.pop(tid, None)
        self.aborted += 1
        self.send(
            TM_LARGE_UPLINK_ABORTION, ABORTION.pack({"tid": tid, "reason": reason}), destination
        )

    def _part(self, req, kind):
        tc = req.decode(PART)
        tid = tc["tid"]
        rx = self.receptions.get(tid)
        if kind == 0:
            if rx is None and len(self.receptions) >= self.max_receptions:
                self.refused += 1
                raise PusFailure(
                    FAILURE_REFUSED,
                    "%d large packet receptions in progress already: at most %d"
                    % (len(self.receptions), self.max_receptions),
                    TRANSACTION_ID.pack(tid),
                )
            rx = self.receptions[tid] = _Reception(tid, self._now(), req.source)
        if rx is None or tc["seq"] != rx.seq + 1:
            self._abort(tid, ABORT_SEQUENCE, req.source)
            raise PusFailure(
                FAILURE_REFUSED,
                "part %d of transaction %d out of sequence" % (tc["seq"], tid),
                TRANSACTION_ID.pack(tid),
            )
        rx.size += len(tc["part"])
        if rx.size > self.max_size:
            self._abort(tid, ABORT_TOO_LARGE, req.source)
            raise PusFailure(FAILURE_REFUSED, "message over %d octets" % self.max_size)
        req.start()
        rx.seq = tc["seq"]
        rx.parts.append(tc["part"])
        rx.last = self._now()
        return rx

    def first(self, req):
        self._part(req, 0)

    def intermediate(self, req):
        self._part(req, 1)

    def last(self, req):
        rx = self._part(req, 2)
        del self.receptions[rx.tid]
        message = b"".join(rx.parts)
        try:
            if self.deliver is not None:
                self.deliver(message)
            else:
                self.app.receive(message)
        except Exception as e:
            self._abort(rx.tid, ABORT_UNDELIVERABLE, rx.source)
            raise PusFailure(FAILURE_REFUSED, "message not delivered: %s" % e) from None
        self.delivered += 1

    def abort_uplink(self, tid):
        """Give up a reception in progress (reported with TM[13,16])."""
        rx = self.receptions.get(tid)
        if rx is None:
            return False
        self._abort(tid, ABORT_COMMANDED, rx.source)
        return True

    # -------------------------------------------------------------------------- downlink

    def downlink(self, message, destination=0):
        """Queue ``message`` for downlink in parts; returns its transaction ID."""
        tid = self.next_tid
        self.next_tid = (tid % 0xFFFF) + 1
        self.outgoing.append([tid, split(bytes(message), self.part_size), 0, destination])
        if self.parts_per_cycle is None:
            self._send_parts(None)
        return tid

    def downlink_report(self, service, subtype, data, destination=0):
        """Build a TM packet of any size (as ``send_tm`` would) and downlink it in parts."""
        app = self.app
        key = (service << 8) | subtype
        n = app.message_counters.get(key, 0)
        app.message_counters[key] = (n + 1) & app.config.message_counter_max
        code = app.config.time
        raw = PusTm(
            app.apid,
            service,
            subtype,
            data,
            app.sequence.next(app.apid),
            n,
            destination,
            code.from_seconds(app.time()) if code is not None else None,
            app.time_ref,
            config=app.config,
        ).pack()
        return self.downlink(raw, destination)

    def abort_downlink(self, tid):
        for i, entry in enumerate(self.outgoing):
            if entry[0] == tid:
                del self.outgoing[i]
                self.aborted += 1
                return True
        return False

    def _send_parts(self, budget):
        while self.outgoing and (budget is None or budget > 0):
            entry = self.outgoing[0]
            tid, parts, i, dest = entry
            if i == 0:
                mt = TM_LARGE_DOWNLINK_FIRST
            elif i == len(parts) - 1:
                mt = TM_LARGE_DOWNLINK_LAST
            else:
                mt = TM_LARGE_DOWNLINK_INTERMEDIATE
            self.send(mt, PART.pack({"tid": tid, "seq": i + 1, "part": parts[i]}), dest)
            entry[2] = i + 1
            if entry[2] >= len(parts):
                self.outgoing.pop(0)
            if budget is not None:
                budget -= 1

    def cyclic(self, now):
        for rx in list(self.receptions.values()):
            if now - rx.last > self.timeout:
                self._abort(rx.tid, ABORT_TIMEOUT, rx.source)
        if self.outgoing:
            self._send_parts(self.parts_per_cycle)


class LargePacketUser(ServiceUser):
    """The service 13 user: uplinks messages in parts, puts downlinked parts back together.

    ``messages`` collects (transaction ID, message) of complete downlinks (and ``on_message``
    is called with them); ``expire(now)`` drops a downlink whose next part is later than
    ``timeout``, counted in ``aborted``; ``abortions`` lists the uplink abortion reports.
    """

    SERVICE = SERVICE_LARGE_PACKET_TRANSFER
    DECODERS = (
        (TM_LARGE_DOWNLINK_FIRST, "decode_first"),
        (TM_LARGE_DOWNLINK_INTERMEDIATE, "decode_intermediate"),
        (TM_LARGE_DOWNLINK_LAST, "decode_last"),
        (TM_LARGE_UPLINK_ABORTION, "decode_abortion"),
    )

    def __init__(self, part_size=256, timeout=10.0):
        super().__init__()
        self.part_size = part_size
        self.timeout = timeout
        self.partial = {}  # (apid, tid) -> [next seq, parts, last time]
        self.messages = []
        self.abortions = []
        self.aborted = 0
        self.on_message = None
        self.next_tid = 1

    def uplink(self, apid, message, tid=None):
        """Send ``message`` in parts; returns the transactions of the part TCs."""
        if tid is None:
            tid = self.next_tid
            self.next_tid = (tid % 0xFFFF) + 1
        parts = split(bytes(message), self.part_size)
        out = []
        for i, p in enumerate(parts):
            if i == 0:
                mt = TC_LARGE_UPLINK_FIRST
            elif i == len(parts) - 1:
                mt = TC_LARGE_UPLINK_LAST
            else:
                mt = TC_LARGE_UPLINK_INTERMEDIATE
            out.append(self.request(apid, mt, PART.pack({"tid": tid, "seq": i + 1, "part": p})))
        return out

    def send_part(self, apid, kind, tid, seq, part):
        """One part TC by hand (``kind`` 0 first, 1 intermediate, 2 last), for tests."""
        mt = (TC_LARGE_UPLINK_FIRST, TC_LARGE_UPLINK_INTERMEDIATE, TC_LARGE_UPLINK_LAST)[kind]
        return self.request(apid, mt, PART.pack({"tid": tid, "seq": seq, "part": part}))

    def _now(self):
        return self.proc.clock.now()

    def _part(self, tm, kind):
        p = PART.unpack(tm.data)
        key = (tm.apid, p["tid"])
        out = {"tid": p["tid"], "seq": p["seq"], "size": len(p["part"])}
        if kind == 0:
            self.partial[key] = [1, [], 0]
        st = self.partial.get(key)
        if st is None or p["seq"] != st[0]:
            if st is not None:
                del self.partial[key]
                self.aborted += 1
            out["error"] = "part out of sequence"
            return out
        st[0] += 1
        st[1].append(p["part"])
        st[2] = self._now()
        if kind == 2:
            del self.partial[key]
            message = b"".join(st[1])
            self.messages.append((p["tid"], message))
            if self.on_message is not None:
                self.on_message(p["tid"], message)
            out["message"] = message
        return out

    def decode_first(self, tm):
        return self._part(tm, 0)

    def decode_intermediate(self, tm):
        return self._part(tm, 1)

    def decode_last(self, tm):
        return self._part(tm, 2)

    def decode_abortion(self, tm):
        out = ABORTION.unpack(tm.data)
        out["reason_name"] = REASON_NAMES.get(out["reason"], "reason %d" % out["reason"])
        self.abortions.append(out)
        return out

    def expire(self, now):
        """Drop downlinks that waited longer than ``timeout`` for a part; returns how many."""
        n = 0
        for key in list(self.partial):
            if now - self.partial[key][2] > self.timeout:
                del self.partial[key]
                n += 1
        self.aborted += n
        return n
