"""SpaceCAN controller (node 0): heartbeat, sync and time, requests tracked per node and service.

Sans-I/O. Feed it `receive(bus, can_id, data, now)` for frames from either bus and
`poll(now)` at `next_deadline()`; send what `take_frames()` gives ((bus, can_id, data) tuples)
and read `take_events()`. Report transmit failures with `tx_error(bus, now)`.
"""

from obsw.spacecan import events as ev
from obsw.spacecan.client import ServiceClient
from obsw.spacecan.fragment import Reassembler, split
from obsw.spacecan.ids import (
    BUS_A,
    FUNCTION_MASK,
    ID_HEARTBEAT,
    ID_REP,
    ID_REQ,
    ID_SCET,
    ID_SYNC,
    ID_UTC,
    NODE_MASK,
    bus_name,
    check_node_id,
    other_bus,
)
from obsw.spacecan.redundancy import BusHealth, ConfigError, check_period
from obsw.spacecan.requests import (  # noqa: F401 (re-exported: the controller's vocabulary)
    ACCEPTED,
    CANCELLED,
    COMPLETED,
    FAILED,
    FINAL,
    QUEUED,
    REJECTED,
    SENT,
    TIMEOUT,
    FailoverPolicy,
    Request,
    RequestError,
)
from obsw.spacecan.timeframes import ScetTime, UtcTime


class Controller(ServiceClient):
    """The SpaceCAN controller: sends heartbeats on the active bus, receives both buses."""

    def __init__(
        self,
        heartbeat_period=0.5,
        sync_period=0,
        policy=None,
        timeout=1.0,
        retries=2,
        completion_timeout=None,
        reassembly_timeout=0.5,
        bus=BUS_A,
    ):
        self.heartbeat_period = check_period("heartbeat_period", heartbeat_period)
        self.sync_period = check_period("sync_period", sync_period)
        self.policy = policy if policy is not None else FailoverPolicy()
        self.timeout = timeout
        self.retries = retries
        self.completion_timeout = completion_timeout
        self.active = bus
        self.nodes = {}  # node id -> NodeDefinition or None
        self.health = [BusHealth(0), BusHealth(1)]
        self.reassembler = Reassembler(reassembly_timeout)
        self.counters = {"rx": 0, "tx": 0, "ignored": 0, "unmatched": 0, "switches": 0}
        self._frames = []
        self._events = []
        self._lines = {}  # (node, service, subtype) -> [Request, ...]; head is in flight
        self._next_hb = None
        self._next_sync = None
        self._timeouts_in_row = 0
        self._switches_without_rx = 0
        self._started = False
        self._start_time = 0

    @classmethod
    def from_config(cls, config, **kw):
        """Build from a spacecan controller JSON dict (interface and channels are the driver's)."""
        return cls(
            heartbeat_period=config.get("heartbeat_period", 0.5),
            sync_period=config.get("sync_period", 0),
            **kw,
        )

    # -- configuration -------------------------------------------------------------------------

    def add_node(self, node_id, nodedef=None):
        """Declare a responder node; its definition is needed to decode (20,2) and (3,25)."""
        self.nodes[check_node_id(node_id)] = nodedef

    # -- sans-I/O interface --------------------------------------------------------------------

    def start(self, now):
        self._started = True
        self._start_time = now
        if self.heartbeat_period:
            self._send_heartbeat(now)
        if self.sync_period:
            self._next_sync = now + self.sync_period

    def take_frames(self):
        out = self._frames
        self._frames = []
        return out

    def take_events(self):
        out = self._events
        self._events = []
        return out

    def _emit(self, kind, now, **fields):
        self._events.append(ev.Event(kind, now, **fields))

    def _send(self, bus, can_id, data):
        self._frames.append((bus, can_id, data))
        self.health[bus].sent()
        self.counters["tx"] += 1

    def tx_error(self, bus, now):
        """The driver could not transmit on bus (error frame, bus-off, no ACK)."""
        h = self.health[bus]
        h.tx_failed(now)
        self._emit(ev.TX_ERROR, now, bus=bus, count=h.errors_since_rx)
        p = self.policy
        if bus == self.active and p.mode == "auto" and h.errors_since_rx >= p.max_tx_errors:
            self._auto_switch(
                now, "%d transmit errors on bus %s" % (h.errors_since_rx, bus_name(bus))
            )

    def receive(self, bus, can_id, data, now):
        """A frame arrived on bus (0 = A, 1 = B)."""
        if not self._started:
            self.start(now)
        if can_id & FUNCTION_MASK != ID_REP:
            self.counters["ignored"] += 1
            return
        self.counters["rx"] += 1
        self.health[bus].received(now)
        if bus == self.active:
            self._timeouts_in_row = 0
            self._switches_without_rx = 0
        elif self.policy.mode == "auto" and self.policy.follow_nodes:
            last = self.health[self.active].last_rx
            quiet = now - (self._start_time if last is None else last)
            if quiet > self._silence():
                self._auto_switch(now, "nodes heard only on bus %s" % bus_name(bus))
        packet = self.reassembler.push(can_id | (bus << 11), data, now)
        if packet is None:
            return
        node = can_id & NODE_MASK
        if len(packet) < 2:
            self._emit(
                ev.DECODE_ERROR, now, node=node, packet=packet, error="packet under 2 bytes"
            )
            return
        self._dispatch(node, packet[0], packet[1], packet[2:], bus, now)

    def poll(self, now):
        """Run what is due at now: heartbeat, sync, request timeouts, fragment expiry."""
        if not self._started:
            self.start(now)
        if self._next_hb is not None and now >= self._next_hb:
            self._send_heartbeat(now)
        if self._next_sync is not None and now >= self._next_sync:
            self._send(self.active, ID_SYNC, b"")
            self._next_sync += self.sync_period
            if self._next_sync <= now:
                self._next_sync = now + self.sync_period
        self.reassembler.expire(now)
        for line in list(self._lines.values()):
            if line and line[0].deadline is not None and now >= line[0].deadline:
                self._expired(line[0], now)

    def next_deadline(self):
        best = self._next_hb
        for t in (self._next_sync, self.reassembler.next_deadline()):
            if t is not None and (best is None or t < best):
                best = t
        for line in self._lines.values():
            if line:
                t = line[0].deadline
                if t is not None and (best is None or t < best):
                    best = t
        return best

    # -- bus management ------------------------------------------------------------------------

    def _send_heartbeat(self, now):
        self._send(self.active, ID_HEARTBEAT, b"")
        if self._next_hb is None:
            self._next_hb = now + self.heartbeat_period
        else:
            self._next_hb += self.heartbeat_period
            if self._next_hb <= now:
                self._next_hb = now + self.heartbeat_period

    def switch_bus(self, now, bus=None, reason="command"):
        """Make bus (default: the other one) active; pending requests are re-sent there."""
        new = other_bus(self.active) if bus is None else bus
        if new not in (0, 1):
            raise ConfigError("bus", "0 (A) or 1 (B)", bus)
        if new == self.active:
            return False
        old = self.active
        self.active = new
        self.counters["switches"] += 1
        self._timeouts_in_row = 0
        self._emit(ev.BUS_SWITCHED, now, old=old, new=new, reason=reason)
        if self.heartbeat_period and self._started:
            self._next_hb = None
            self._send_heartbeat(now)  # responders following heartbeats see the new bus at once
        for line in self._lines.values():
            if line and line[0].status == SENT:
                self._transmit(line[0], now, count=False)
        return True

    def _silence(self):
        if self.policy.silence is not None:
            return self.policy.silence
        return 4 * (self.heartbeat_period or 0.5)

    def _auto_switch(self, now, reason):
        if self._switches_without_rx >= self.policy.max_switches:
            return
        self._switches_without_rx += 1
        self.switch_bus(now, reason=reason)

    def bus_status(self, now):
        """Both buses' health, the active one marked."""
        window = (self.heartbeat_period or 0.5) * 4
        return [h.report(now, window, h.bus == self.active) for h in self.health]

    # -- broadcasts ----------------------------------------------------------------------------

    def send_sync(self, now=None):
        self._send(self.active, ID_SYNC, b"")

    def send_scet(self, coarse_time, fine_time=0, now=None):
        self._send(self.active, ID_SCET, ScetTime(coarse_time, fine_time).pack())

    def send_utc(self, day, ms_of_day, sub_ms=0, now=None):
        self._send(self.active, ID_UTC, UtcTime(day, ms_of_day, sub_ms).pack())

    def send_raw(self, node_id, data):
        """Raw data mode (no packets): one REQ frame of up to 8 bytes."""
        if len(data) > 8:
            raise RequestError("raw frame data is at most 8 bytes, got %d" % len(data), node_id)
        self._send(self.active, ID_REQ + check_node_id(node_id), bytes(data))

    # -- requests ------------------------------------------------------------------------------

    def request(self, node_id, service, subtype, data, now, timeout=None, retries=None):
        """Queue a service request to node_id; returns the Request that tracks it."""
        check_node_id(node_id)
        if not isinstance(now, (int, float)) or isinstance(now, bool):
            raise RequestError("now must be a time in seconds, got %r" % (now,), node_id)
        data = bytes(data)
        if len(data) + 2 > 1536:
            raise RequestError("request too long: %d bytes of data" % len(data), node_id)
        if not self._started:
            self.start(now)
        t = self.timeout if timeout is None else timeout
        ct = self.completion_timeout if self.completion_timeout is not None else t
        req = Request(
            node_id, service, subtype, data, t, self.retries if retries is None else retries, ct
        )
        line = self._lines.get(req.key)
        if line is None:
            line = self._lines[req.key] = []
        line.append(req)
        if len(line) == 1:
            self._transmit(req, now)
        return req

    def _transmit(self, req, now, count=True):
        if count:
            req.attempts += 1
        req.status = SENT
        req.bus = self.active
        req.sent_at = now
        req.deadline = now + req.timeout
        can_id = ID_REQ + req.node_id
        for frame in split(bytes((req.service, req.subtype)) + req.data):
            self._send(self.active, can_id, frame)

    def _finish(self, req, status, now, error=None):
        req.status = status
        req.deadline = None
        if error is not None:
            req.error = error
        line = self._lines.get(req.key)
        if line and req in line:
            head = line[0] is req
            line.remove(req)
            if not line:
                del self._lines[req.key]
            elif head:
                self._transmit(line[0], now)
        self._emit(ev.REQUEST_DONE, now, request=req)
        if req.on_done is not None:
            req.on_done(req)

    def _expired(self, req, now):
        if req.status == SENT:
            self._timeouts_in_row += 1
            p = self.policy
            if p.mode == "auto" and self._timeouts_in_row >= p.max_timeouts:
                before = self.active
                self._auto_switch(
                    now,
                    "%d request timeouts on bus %s" % (self._timeouts_in_row, bus_name(before)),
                )
                if self.active != before:
                    return  # switch_bus re-sent it
            if req.attempts <= req.retries:
                self._transmit(req, now)
                return
            self._finish(
                req,
                TIMEOUT,
                now,
                "no answer from node %d after %d attempts" % (req.node_id, req.attempts),
            )
        else:
            self._finish(
                req,
                TIMEOUT,
                now,
                "node %d accepted but did not complete in %.3f s"
                % (req.node_id, req.completion_timeout),
            )

    def cancel(self, req, now):
        """Stop tracking req (a queued one is never sent)."""
        if not req.done:
            self._finish(req, CANCELLED, now, "cancelled")

    def pending(self):
        """All requests not yet done, in flight first."""
        out = []
        for line in self._lines.values():
            out.extend(line)
        return out

    def _head(self, node, service, subtype):
        line = self._lines.get((node, service, subtype))
        if line and line[0].status in (SENT, ACCEPTED):
            return line[0]
        return None
