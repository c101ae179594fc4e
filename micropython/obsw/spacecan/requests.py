"""SpaceCAN controller request tracking: request states, the Request record, failover policy."""

from obsw.spacecan.redundancy import ConfigError, check_period

# Request states.
QUEUED = "queued"
SENT = "sent"
ACCEPTED = "accepted"
COMPLETED = "completed"
REJECTED = "rejected"
FAILED = "failed"
TIMEOUT = "timeout"
CANCELLED = "cancelled"
FINAL = (COMPLETED, REJECTED, FAILED, TIMEOUT, CANCELLED)


class RequestError(ValueError):
    """A request that cannot be made (unknown node, bad arguments)."""

    def __init__(self, msg, node_id=None):
        super().__init__(msg)
        self.node_id = node_id


class Request:
    """One tracked request: its state, verification reports seen and its result.

    The wire carries no request id, so requests with the same (node, service, subtype) wait in
    line behind each other; reports are matched to the oldest one sent.
    """

    def __init__(self, node_id, service, subtype, data, timeout, retries, completion_timeout):
        self.node_id = node_id
        self.service = service
        self.subtype = subtype
        self.data = data
        self.timeout = timeout
        self.retries = retries
        self.completion_timeout = completion_timeout
        self.status = QUEUED
        self.attempts = 0
        self.bus = None
        self.sent_at = None
        self.deadline = None
        self.reports = []  # verification subtypes in arrival order (1, 7 ...)
        self.result = None
        self.error = None
        self.on_done = None

    @property
    def key(self):
        return (self.node_id, self.service, self.subtype)

    @property
    def done(self):
        return self.status in FINAL

    @property
    def ok(self):
        return self.status == COMPLETED

    def __repr__(self):
        return "Request(node=%d, (%d,%d), %s, attempts=%d)" % (
            self.node_id,
            self.service,
            self.subtype,
            self.status,
            self.attempts,
        )


class FailoverPolicy:
    """When the controller leaves its active bus by itself.

    mode "manual": only on command. mode "auto": after `max_timeouts` request timeouts in a row
    or `max_tx_errors` transmit errors in a row on the active bus with nothing received on it in
    between, or (`follow_nodes`) when nodes are heard on the standby bus while the active one
    has been silent for `silence` seconds (default four heartbeat periods); at most
    `max_switches` times until a frame arrives on the bus switched to.
    """

    def __init__(
        self,
        mode="auto",
        max_timeouts=2,
        max_tx_errors=3,
        max_switches=2,
        follow_nodes=True,
        silence=None,
    ):
        if mode not in ("auto", "manual"):
            raise ConfigError("failover mode", "'auto' or 'manual'", mode)
        for key, v in (
            ("max_timeouts", max_timeouts),
            ("max_tx_errors", max_tx_errors),
            ("max_switches", max_switches),
        ):
            if not isinstance(v, int) or isinstance(v, bool) or v < 1:
                raise ConfigError(key, "an integer >= 1", v)
        self.mode = mode
        self.max_timeouts = max_timeouts
        self.max_tx_errors = max_tx_errors
        self.max_switches = max_switches
        self.follow_nodes = follow_nodes
        self.silence = check_period("silence", silence) if silence is not None else None
