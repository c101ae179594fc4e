"""The ground side of PUS: a user process whose service users send TCs and decode TM.

``send`` packs a TC and returns a ``Transaction``; ``receive(tm_bytes)`` decodes a TM, gives
verification reports to the transaction they name (by request ID) and other TM to the
service user of its type, whose decoded values also join the oldest open transaction that
expects that message type from that APID. Sans-I/O like the on-board side: TC bytes go to
``out``, time comes from ``clock.now()``.
"""

from obsw.pus.config import DEFAULT
from obsw.pus.packets import ACK_ALL, ACK_COMPLETION, PusError
from obsw.pus.services.s01_verification import (
    ACCEPTANCE,
    COMPLETION,
    ROUTING,
    START,
    VerificationUser,
    describe,
)
from obsw.pus.tc import PusTc
from obsw.pus.tm import PusTm
from obsw.spp import SequenceCounter, SequenceMonitor


class Transaction:
    """One request and what came back for it.

    ``reports`` are the decoded service 1 reports in arrival order, ``replies`` the decoded
    response TM. ``done`` turns True with the completion report (or any failure report, or
    when the request asked for no completion report and its reply came).
    """

    def __init__(self, tc, expect, sent_at):
        self.tc = tc
        self.request_id = tc.request_id()
        self.expect = expect  # the (service, subtype) of the response TM, or None
        self.sent_at = sent_at
        self.reports = []
        self.replies = []
        self.failure = None  # the decoded failure report
        self.done = False
        self.done_at = None

    @property
    def ok(self):
        return self.done and self.failure is None

    def stage(self, stage):
        """False if a failure report of ``stage`` came, True if a success report, else None."""
        seen = None
        for r in self.reports:
            if r["stage"] == stage:
                if not r["success"]:
                    return False
                seen = True
        return seen

    @property
    def accepted(self):
        return self.stage(ACCEPTANCE)

    @property
    def started(self):
        return self.stage(START)

    @property
    def completed(self):
        return self.stage(COMPLETION)

    @property
    def reply(self):
        """The first decoded response, or None."""
        return self.replies[0] if self.replies else None

    def verification(self):
        """The reports as short text, e.g. ['acceptance success', 'completion success']."""
        return [describe(r) for r in self.reports]

    def __repr__(self):
        return "Transaction(TC[%d,%d] apid=%d seq=%d, %s)" % (
            self.tc.service,
            self.tc.subtype,
            self.tc.apid,
            self.tc.seq_count,
            "failed" if self.failure else ("done" if self.done else "open"),
        )


class UserProcess:
    """The ground application process: service users, transactions, TM decoding."""

    def __init__(self, out, clock, *, source_id=0, config=DEFAULT, keep=64):
        self._put = out.put if hasattr(out, "put") else out
        self.clock = clock
        self.source_id = source_id
        self.config = config
        self.keep = keep  # open transactions kept before the oldest is given up
        self.users = {}
        self.sequence = SequenceCounter()
        self.monitor = SequenceMonitor()
        self.open = []  # transactions not yet done, oldest first
        self.counters = {}
        self.listeners = []  # callables(tm, decoded, transaction) for every TM
        self.verification = self.register(VerificationUser())

    def register(self, user):
        self.users[user.SERVICE] = user
        user.attach(self)
        return user

    def count(self, name):
        self.counters[name] = self.counters.get(name, 0) + 1

    def send(self, apid, service, subtype, data=b"", expect=None, ack=ACK_ALL):
        """Pack and send a TC; returns its Transaction."""
        tc = PusTc(
            apid,
            service,
            subtype,
            data,
            self.sequence.next(apid),
            ack,
            self.source_id,
            config=self.config,
        )
        raw = tc.pack()
        tx = Transaction(tc, expect, self.clock.now())
        self.open.append(tx)
        if len(self.open) > self.keep:
            self.open.pop(0)
            self.count("given_up")
        self._put(raw)
        self.count("tc_sent")
        return tx

    def receive(self, data):
        """Decode one TM; returns ``(tm, decoded, transaction)`` or None if it was dropped."""
        try:
            tm = PusTm.unpack(data, self.config)
        except PusError:
            self.count("malformed")
            return None
        self.count("tm_received")
        gap = self.monitor.observe(tm.apid, tm.seq_count)
        if gap:
            self.count("sequence_gaps")
        user = self.users.get(tm.service)
        fn = user.decoder(tm.subtype) if user is not None else None
        if fn is None:
            self.count("unknown_type")
            return self._publish(tm, None, None)
        try:
            decoded = fn(tm)
        except (ValueError, KeyError, IndexError, TypeError):
            self.count("undecodable")
            return self._publish(tm, None, None)
        if tm.service == 1:
            tx = self._verified(decoded)
        else:
            tx = self._answered(tm, decoded)
        return self._publish(tm, decoded, tx)

    def _publish(self, tm, decoded, tx):
        for fn in self.listeners:
            fn(tm, decoded, tx)
        return tm, decoded, tx

    def _find(self, rid):
        for tx in self.open:
            if tx.request_id == rid:
                return tx
        return None

    def _verified(self, report):
        tx = self._find(report["request_id"])
        if tx is None:
            self.count("unmatched_reports")
            return None
        tx.reports.append(report)
        if not report["success"] or report["stage"] in (COMPLETION, ROUTING):
            if not report["success"]:
                tx.failure = report
            self._close(tx)
        return tx

    def _answered(self, tm, decoded):
        """The open request a response TM answers (a response carries no request ID): the
        oldest one of its type that the process accepted, else the oldest of its type (a
        request whose TC was lost, e.g. to a restart, never takes another's response)."""
        key = (tm.service, tm.subtype)
        waiting = [tx for tx in self.open if tx.expect == key and tx.tc.apid == tm.apid]
        if not waiting:
            return None
        accepted = [tx for tx in waiting if tx.accepted]
        tx = accepted[0] if accepted else waiting[0]
        tx.replies.append(decoded)
        if not tx.tc.ack & ACK_COMPLETION:
            self._close(tx)
        return tx

    def _close(self, tx):
        tx.done = True
        tx.done_at = self.clock.now()
        if tx in self.open:
            self.open.remove(tx)
