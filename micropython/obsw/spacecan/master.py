"""The OBC's SpaceCAN master as an interaction-layer component wrapping a Controller.

``MASTER`` is its interface, declared once; ``SpaceCanMaster`` is the provider's
implementation. Requests take time on the bus, so every request operation is asynchronous:
the caller's ``Pending`` is accepted at once, gets a status update when the request is sent,
re-sent (retry, other bus) or accepted by the node, and completes with the request's record
when the controller's ``Request`` completes, or fails with a ``ComponentError`` whose code says
why (``REJECTED`` (1,2), ``FAILED`` (1,8), ``TIMEOUT``, ``CANCELLED``, ``BAD_REQUEST``).

Sans-I/O: the master is also a bus node (``receive``/``poll``/``next_deadline``/
``take_frames``/``take_events``/``tx_error``, delegated to the controller), so a driver moves
its frames like a controller's: the simulated network in tests, the python-can adapter on the
host. ``step(now)`` (= ``poll``) runs the controller's deadlines, turns its events into
publications and pushes status updates; ``now`` for new requests comes from the IL node's
clock, or from the last step when unbound.
"""

from obsw.compat import const
from obsw.il.errors import ComponentError
from obsw.il.interface import DATA, INFO, LOW, MEDIUM, Attribute, Event, Interface, Operation
from obsw.spacecan import events as ev
from obsw.spacecan import packets as pk
from obsw.spacecan.ids import BUS_NAMES, bus_name
from obsw.spacecan.requests import CANCELLED, COMPLETED, FAILED, REJECTED, TIMEOUT

MASTER_NAME = "SpaceCanMaster"
MASTER_ID = const(0x60)

# ComponentError codes of a request that did not complete
BAD_REQUEST = "BAD_REQUEST"  # refused before anything was sent (unknown node, bad arguments)
ERROR_CODES = {
    REJECTED: "REJECTED",
    FAILED: "FAILED",
    TIMEOUT: "TIMEOUT",
    CANCELLED: "CANCELLED",
}


def _request(name, id, params, description=""):
    return Operation(name, id, ("node_id",) + params, asynchronous=True, description=description)


MASTER = Interface(
    MASTER_NAME,
    MASTER_ID,
    [
        Attribute("active_bus", 1, DATA, type="u8", description="0 = bus A, 1 = bus B"),
        Attribute("bus_a_state", 2, DATA, type="str", description="ok, silent or error"),
        Attribute("bus_b_state", 3, DATA, type="str", description="ok, silent or error"),
        Attribute("rx_frames", 4, DATA, type="u32", description="reply frames received"),
        Attribute("tx_frames", 5, DATA, type="u32", description="frames sent"),
        Attribute("tx_errors", 6, DATA, type="u32", description="transmit errors, both buses"),
        Attribute("bus_switches", 7, DATA, type="u32", description="changes of active bus"),
        Attribute("pending_requests", 8, DATA, type="u16", description="requests not done"),
        Attribute("bus_status", 9, DATA, description="both buses' health records"),
        _request("send_command", 16, ("service", "subtype", "data"), "data after the subtype"),
        _request("call_function", 17, ("function_id", "args"), "(8,1), args {arg id: value}"),
        _request("request_parameters", 18, ("parameter_ids",), "(20,1), result {id: value}"),
        _request("set_parameters", 19, ("values",), "(20,3), values {id: value}"),
        _request("ping", 20, (), "(17,1)"),
        _request("request_housekeeping", 21, ("report_ids",), "(3,27)"),
        _request("enable_housekeeping", 22, ("report_ids",), "(3,5)"),
        _request("disable_housekeeping", 23, ("report_ids",), "(3,6)"),
        Operation("switch_bus", 24, ("bus",), returns="u8", description="0/A, 1/B, None: other"),
        Event("housekeeping_report", 32, INFO, fields=("node", "report_id", "values")),
        Event("parameter_report", 33, INFO, fields=("node", "values")),
        Event("verification_failure", 34, LOW, fields=("node", "service", "subtype", "report")),
        Event("request_timeout", 35, MEDIUM, fields=("node", "service", "subtype", "attempts")),
        Event("bus_failover", 36, MEDIUM, fields=("old", "new", "reason")),
    ],
    description="the OBC's SpaceCAN controller: requests to nodes, reports, bus status",
)


def record(req):
    """What a finished (or running) request looks like to an IL caller."""
    return {
        "node": req.node_id,
        "service": req.service,
        "subtype": req.subtype,
        "status": req.status,
        "bus": req.bus,
        "attempts": req.attempts,
        "reports": list(req.reports),
        "result": req.result,
    }


def _bus_number(bus):
    if bus is None or bus == 0 or bus == 1:
        return bus
    if bus in BUS_NAMES:
        return BUS_NAMES.index(bus)
    raise ComponentError(BAD_REQUEST, "bus must be 0, 1, 'A', 'B' or None, got %r" % (bus,))


class SpaceCanMaster:
    """The provider of ``MASTER`` around ``controller`` (see the module text).

    ``clock`` is a function giving the time for new requests; by default the IL node's clock
    once provided. ``status_period`` is how often bus states are re-evaluated and published.
    ``keep_events`` bounds the controller events kept for ``take_events`` (a driver's
    listeners); older ones are dropped and counted in ``dropped_events``.
    """

    def __init__(self, controller, clock=None, status_period=0.5, keep_events=64):
        self.controller = controller
        self.clock = clock
        self.status_period = status_period
        self.keep_events = keep_events
        self.dropped_events = 0
        self.il = None
        self.active_bus = controller.active
        self.bus_a_state = "silent"
        self.bus_b_state = "silent"
        self._now = 0
        self._jobs = {}  # id(request) -> [job, request, last reported (status, bus, attempts)]
        self._events = []
        self._next_status = None

    def il_bind(self, provider):
        self.il = provider
        if self.clock is None:
            self.clock = provider.node.clock.now

    def _time(self):
        return self.clock() if self.clock is not None else self._now

    # -- data attributes read live from the controller ------------------------------------------

    @property
    def rx_frames(self):
        return self.controller.counters["rx"]

    @property
    def tx_frames(self):
        return self.controller.counters["tx"]

    @property
    def tx_errors(self):
        h = self.controller.health
        return h[0].tx_errors + h[1].tx_errors

    @property
    def bus_switches(self):
        return self.controller.counters["switches"]

    @property
    def pending_requests(self):
        return len(self.controller.pending())

    @property
    def bus_status(self):
        return self.controller.bus_status(self._time())

    # -- the bus node, driven by a simulated network or an adapter ------------------------------

    def start(self, now):
        self._now = now
        self.controller.start(now)
        self._status(now)

    def receive(self, bus, can_id, data, now):
        self._now = now
        self.controller.receive(bus, can_id, data, now)
        self._drain(now)

    def step(self, now):
        """Run what is due at ``now``: controller deadlines, events, status updates."""
        self._now = now
        self.controller.poll(now)
        self._drain(now)
        if self._next_status is None or now >= self._next_status:
            self._status(now)

    poll = step

    def next_deadline(self):
        best = self.controller.next_deadline()
        t = self._next_status
        if t is not None and (best is None or t < best):
            best = t
        return best

    def take_frames(self):
        return self.controller.take_frames()

    def take_events(self):
        out = self._events
        self._events = []
        return out

    def tx_error(self, bus, now):
        self._now = now
        self.controller.tx_error(bus, now)
        self._drain(now)

    # -- operations ----------------------------------------------------------------------------

    def _start(self, job, make):
        now = self._time()
        try:
            req = make(now)
        except ValueError as e:  # RequestError, NodeIdError, ServicePacketError, EncodingError
            raise ComponentError(BAD_REQUEST, str(e), {"operation": job.operation.name})  # noqa: B904
        entry = [job, req, None]
        self._jobs[id(req)] = entry
        req.on_done = self._done
        self._progress(entry)

    def send_command(self, job, node_id, service, subtype, data):
        c = self.controller
        raw = b"" if data is None else data
        try:
            raw = bytes(raw) if isinstance(raw, list) else raw
        except ValueError:  # an item outside 0..255
            pass
        if not isinstance(raw, (bytes, bytearray)):
            raise ComponentError(BAD_REQUEST, "data must be bytes, got %r" % (data,))
        data = raw
        self._start(job, lambda now: c.request(node_id, service, subtype, data, now))

    def call_function(self, job, node_id, function_id, args):
        c = self.controller
        self._start(job, lambda now: c.call_function(node_id, function_id, now, args))

    def request_parameters(self, job, node_id, parameter_ids):
        c = self.controller
        self._start(job, lambda now: c.request_parameters(node_id, parameter_ids, now))

    def set_parameters(self, job, node_id, values):
        c = self.controller
        self._start(job, lambda now: c.set_parameters(node_id, values, now))

    def ping(self, job, node_id):
        c = self.controller
        self._start(job, lambda now: c.ping(node_id, now))

    def request_housekeeping(self, job, node_id, report_ids):
        c = self.controller
        self._start(job, lambda now: c.request_housekeeping(node_id, report_ids, now))

    def enable_housekeeping(self, job, node_id, report_ids):
        c = self.controller
        self._start(job, lambda now: c.enable_housekeeping(node_id, report_ids, now))

    def disable_housekeeping(self, job, node_id, report_ids):
        c = self.controller
        self._start(job, lambda now: c.disable_housekeeping(node_id, report_ids, now))

    def switch_bus(self, bus=None):
        """Make ``bus`` active (requests in flight are re-sent there); return the active bus."""
        now = self._time()
        self.controller.switch_bus(now, _bus_number(bus), reason="commanded")
        self._drain(now)
        return self.controller.active

    # -- completion and status -----------------------------------------------------------------

    def _done(self, req):
        entry = self._jobs.pop(id(req), None)
        if entry is None:
            return
        job = entry[0]
        if req.status == COMPLETED:
            job.succeed(record(req))
            return
        code = ERROR_CODES.get(req.status, req.status)
        message = req.error or "request %s" % req.status
        job.fail(ComponentError(code, message, record(req)))

    def _progress(self, entry):
        req = entry[1]
        seen = (req.status, req.bus, req.attempts)
        if seen != entry[2]:
            entry[2] = seen
            entry[0].update(
                {
                    "status": req.status,
                    "bus": req.bus,
                    "attempt": req.attempts,
                    "reports": list(req.reports),
                }
            )

    def _publish(self, name, value):
        if self.il is not None:
            self.il.update(name, value)
        else:
            setattr(self, name, value)

    def _emit(self, name, payload):
        if self.il is not None:
            self.il.emit(name, payload)

    def _status(self, now):
        self._next_status = now + self.status_period if self.status_period else None
        c = self.controller
        if c.active != self.active_bus:
            self._publish("active_bus", c.active)
        window = (c.heartbeat_period or 0.5) * 4
        a = c.health[0].state(now, window)
        b = c.health[1].state(now, window)
        if a != self.bus_a_state:
            self._publish("bus_a_state", a)
        if b != self.bus_b_state:
            self._publish("bus_b_state", b)

    def _drain(self, now):
        events = self.controller.take_events()
        for e in events:
            self._event(e, now)
        if self.keep_events and events:
            kept = self._events
            kept.extend(events)
            extra = len(kept) - self.keep_events
            if extra > 0:
                del kept[:extra]
                self.dropped_events += extra
        for entry in list(self._jobs.values()):
            self._progress(entry)

    def _event(self, e, now):
        kind = e.kind
        if kind == ev.HOUSEKEEPING_REPORT:
            self._emit(
                "housekeeping_report",
                {"node": e.node, "report_id": e.report_id, "values": e.values},
            )
        elif kind == ev.PARAMETER_REPORT:
            self._emit("parameter_report", {"node": e.node, "values": e.values})
        elif kind == ev.VERIFICATION:
            if e.subtype == pk.ACCEPT_FAIL or e.subtype == pk.COMPLETE_FAIL:
                self._emit(
                    "verification_failure",
                    {
                        "node": e.node,
                        "service": e.service,
                        "subtype": e.req_subtype,
                        "report": e.subtype,
                        "matched": e.request is not None,
                    },
                )
        elif kind == ev.REQUEST_DONE:
            req = e.request
            if req.status == TIMEOUT:
                self._emit(
                    "request_timeout",
                    {
                        "node": req.node_id,
                        "service": req.service,
                        "subtype": req.subtype,
                        "attempts": req.attempts,
                        "error": req.error,
                    },
                )
        elif kind == ev.BUS_SWITCHED:
            self._emit(
                "bus_failover",
                {"old": bus_name(e.old), "new": bus_name(e.new), "reason": e.reason},
            )
            self._status(now)
