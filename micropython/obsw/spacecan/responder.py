"""SpaceCAN responder (node 1..127): services 1, 3, 8, 17, 20 and bus failover by heartbeat.

Sans-I/O, the same interface as the controller: `receive(bus, can_id, data, now)`,
`poll(now)` at `next_deadline()`, `take_frames()`, `take_events()`. Both buses are received;
replies go out on the bus the request came in on, periodic reports on the active bus.
"""

import struct

from obsw.compat import const, micropython
from obsw.spacecan import encoding as enc
from obsw.spacecan import events as ev
from obsw.spacecan import packets as pk
from obsw.spacecan.fragment import MAX_PACKET_SIZE, Reassembler, split
from obsw.spacecan.ids import (
    BUS_A,
    ID_HEARTBEAT,
    ID_REP,
    ID_REQ,
    ID_SCET,
    ID_SYNC,
    ID_UTC,
    bus_name,
    check_node_id,
)
from obsw.spacecan.redundancy import BusHealth, HeartbeatMonitor
from obsw.spacecan.timeframes import CanFrameLengthError, ScetTime, UtcTime

_CANNED_MAX = const(64)  # verification report frames kept ready
_PING_REPORT_FRAME = split(bytes((pk.SERVICE_TEST, pk.PING_REPORT)))[0]
_PING_KEY = const((17 << 8) | 1)  # (pk.SERVICE_TEST << 8) | pk.PING
_PARAM_REQUEST_KEY = const((20 << 8) | 1)  # (pk.SERVICE_PARAMETER << 8) | pk.PARAM_REQUEST

_MIN_HK_INTERVAL = 0.01


class _Reject(Exception):
    """A request the responder refuses: answered with (1,2)."""

    def __init__(self, reason):
        super().__init__(reason)
        self.reason = reason


class Responder:
    """A SpaceCAN responder node serving its NodeDefinition.

    Application hooks (all optional): `on_function(function_id, args) -> bool` (False or an
    exception gives (1,8)); `on_parameters_set(values) -> bool` vetoes a (20,3);
    `on_raw(data, bus)` gets REQ frames in raw data mode (`use_packets=False`).
    `event_kinds`: None (every event is kept for `take_events`) or the kinds the application
    takes; events of other kinds are not even built (a SYNC on a loaded bus costs no garbage).

    A loaded bus is mostly heartbeats, time frames and other nodes' traffic: `receive` takes
    those first and in a few dozen bytecodes, with no call and no allocation for a heartbeat
    but the float of its deadline; a request of one frame skips the reassembler's bookkeeping
    for multi-frame packets, and the replies that depend on nothing but the request (ping,
    verification reports) are sent as frames made once.
    """

    def __init__(
        self,
        node_id,
        nodedef,
        heartbeat_period=0.5,
        max_miss_heartbeat=3,
        max_bus_switch=False,
        follow_heartbeat=True,
        reassembly_timeout=0.5,
        use_packets=True,
        bus=BUS_A,
    ):
        self.node_id = check_node_id(node_id)
        self.nodedef = nodedef
        self.monitor = HeartbeatMonitor(
            heartbeat_period, max_miss_heartbeat, max_bus_switch, follow_heartbeat, bus
        )
        self.use_packets = use_packets
        self.health = [BusHealth(0), BusHealth(1)]
        self.reassembler = Reassembler(reassembly_timeout)
        self.counters = {
            "rx": 0,
            "tx": 0,
            "requests": 0,
            "rejected": 0,
            "ignored": 0,
            "bad_frames": 0,
        }
        self.scet = None
        self.utc = None
        self.on_function = None
        self.on_parameters_set = None
        self.on_raw = None
        self.req_id = ID_REQ + node_id
        self._rep_id = ID_REP + node_id
        self.event_kinds = None
        self._frames = []
        self._canned = {}  # verification report frames by bus, subtype, service, subtype
        self._ping_frames = [None, None]  # the three replies to a ping, by bus
        self._events = []
        self._hk_due = {}  # report id -> next due time (None: set at the next poll)
        self._started = False
        for rid, r in nodedef.reports.items():
            if r.enabled:
                self._hk_due[rid] = None
        # by (service << 8) | subtype: an int key, no tuple made per request
        self._handlers = {
            (pk.SERVICE_TEST << 8) | pk.PING: self._ping,
            (pk.SERVICE_PARAMETER << 8) | pk.PARAM_REQUEST: self._param_request,
            (pk.SERVICE_PARAMETER << 8) | pk.PARAM_SET: self._param_set,
            (pk.SERVICE_HOUSEKEEPING << 8) | pk.HK_ENABLE: self._hk_enable,
            (pk.SERVICE_HOUSEKEEPING << 8) | pk.HK_DISABLE: self._hk_disable,
            (pk.SERVICE_HOUSEKEEPING << 8) | pk.HK_ONE_SHOT: self._hk_one_shot,
            (pk.SERVICE_FUNCTION << 8) | pk.FUNCTION_PERFORM: self._function,
        }

    @classmethod
    def from_config(cls, config, nodedef, **kw):
        """Build from a spacecan responder JSON dict (interface and channels are the driver's)."""
        return cls(
            config["node_id"],
            nodedef,
            heartbeat_period=config.get("heartbeat_period", 0.5),
            max_miss_heartbeat=config.get("max_miss_heartbeat", 3),
            max_bus_switch=config.get("max_bus_switch", False),
            use_packets=config.get("use_packets", True),
            **kw,
        )

    @property
    def active(self):
        return self.monitor.active

    # -- sans-I/O interface --------------------------------------------------------------------

    def start(self, now):
        self._started = True
        self.monitor.start(now)
        for rid in self._hk_due:
            if self._hk_due[rid] is None:
                self._hk_due[rid] = now + self._interval(rid)

    def _interval(self, rid):
        return max(self.nodedef.reports[rid].interval, _MIN_HK_INTERVAL)

    @micropython.native
    def take_frames(self):
        """The frames to send, as a list that is the caller's; with nothing to send, a shared
        empty list (handed out instead of a new one in every poll: garbage costs a board)."""
        out = self._frames
        if out:
            self._frames = []
        return out

    @micropython.native
    def take_events(self):
        """The events since the last call; like ``take_frames``, an empty result is shared."""
        out = self._events
        if out:
            self._events = []
        return out

    def _emit(self, kind, now, **fields):
        kinds = self.event_kinds
        if kinds is None or kind in kinds:
            self._events.append(ev.Event(kind, now, **fields))

    def tx_error(self, bus, now):
        h = self.health[bus]
        h.tx_failed(now)
        self._emit(ev.TX_ERROR, now, bus=bus, count=h.errors_since_rx)

    @micropython.native
    def receive(self, bus, can_id, data, now):
        """A frame arrived on bus (0 = A, 1 = B)."""
        if can_id == ID_HEARTBEAT and self._started and not data:
            # the bulk of a bus's traffic, inline: _count_rx, BusHealth.received and
            # HeartbeatMonitor.heartbeat's usual case (a heartbeat on the active bus)
            self.counters["rx"] += 1
            h = self.health[bus]
            h.rx_frames += 1
            h.last_rx = now
            h.errors_since_rx = 0
            h.heartbeats += 1
            h.last_heartbeat = now
            m = self.monitor
            if bus == m.active:
                m.last[bus] = now
                m.switches_without_heartbeat = 0
                if m.period:
                    m.deadline = now + m.window_s
                return
            old = m.active
            reason = m.heartbeat(bus, now)
            if reason is not None:
                self._emit(ev.BUS_SWITCHED, now, old=old, new=m.active, reason=reason)
            return
        if not self._started:
            self.start(now)
        if can_id == self.req_id:
            self.counters["rx"] += 1
            h = self.health[bus]  # BusHealth.received, inline
            h.rx_frames += 1
            h.last_rx = now
            h.errors_since_rx = 0
            if not self.use_packets:
                if self.on_raw is not None:
                    self.on_raw(bytes(data), bus)
                return
            ra = self.reassembler
            if not ra._partial and len(data) >= 2 and data[0] == 0 and data[1] == 0:
                # Reassembler.push's packet of one frame with nothing pending, inline
                c = ra.counters
                c["frames"] += 1
                c["packets"] += 1
                if type(data) is bytes:  # served in place: the packet starts at data[2]
                    self._serve(data, bus, now, 2)
                    return
                packet = bytes(data[2:])
            else:
                packet = ra.push(can_id | (bus << 11), data, now)
            if packet is not None:
                self._serve(packet, bus, now)
        elif can_id == ID_HEARTBEAT:
            if len(data):
                self._bad(bus, can_id, now, CanFrameLengthError("heartbeat", 0, len(data)))
                return
            self._count_rx(bus, now)
            self.health[bus].heartbeats += 1
            self.health[bus].last_heartbeat = now
            old = self.monitor.active
            reason = self.monitor.heartbeat(bus, now)
            if reason is not None:
                self._emit(ev.BUS_SWITCHED, now, old=old, new=self.monitor.active, reason=reason)
        elif can_id == ID_SYNC:
            if len(data):
                self._bad(bus, can_id, now, CanFrameLengthError("sync", 0, len(data)))
                return
            self._count_rx(bus, now)
            kinds = self.event_kinds
            if kinds is None or ev.SYNC in kinds:
                self._events.append(ev.Event(ev.SYNC, now, bus=bus))
        elif can_id == ID_SCET or can_id == ID_UTC:
            try:
                t = ScetTime.unpack(data) if can_id == ID_SCET else UtcTime.unpack(data)
            except ValueError as e:
                self._bad(bus, can_id, now, e)
                return
            self._count_rx(bus, now)
            if can_id == ID_SCET:
                self.scet = t
                self._emit(ev.SCET, now, bus=bus, value=t)
            else:
                self.utc = t
                self._emit(ev.UTC, now, bus=bus, value=t)
        else:
            self.counters["ignored"] += 1

    @micropython.native
    def _count_rx(self, bus, now):
        self.counters["rx"] += 1
        h = self.health[bus]  # BusHealth.received, inline
        h.rx_frames += 1
        h.last_rx = now
        h.errors_since_rx = 0

    def _bad(self, bus, can_id, now, error):
        self.counters["bad_frames"] += 1
        self.health[bus].bad_frames += 1
        self._emit(ev.FRAME_ERROR, now, bus=bus, can_id=can_id, error=str(error))

    @micropython.native
    def poll(self, now):
        """Heartbeat deadline, periodic housekeeping and fragment expiry."""
        if not self._started:
            self.start(now)
        m = self.monitor
        deadline = m.deadline
        if deadline is not None and now >= deadline:  # else HeartbeatMonitor.poll does nothing
            old = m.active
            reason = m.poll(now)
            if reason is not None:
                self._emit(ev.BUS_SWITCHED, now, old=old, new=m.active, reason=reason)
        if self.reassembler._partial:  # else expire has nothing to drop
            self.reassembler.expire(now)
        hk_due = self._hk_due
        for rid in hk_due:
            due = hk_due[rid]
            if due is None:
                self._hk_due[rid] = now + self._interval(rid)
            elif now >= due:
                interval = self._interval(rid)
                self._reply(
                    self.monitor.active,
                    pk.SERVICE_HOUSEKEEPING,
                    pk.HK_REPORT,
                    pk.pack_hk(self.nodedef, rid),
                )
                due += interval
                self._hk_due[rid] = due if due > now else now + interval

    def next_deadline(self):
        best = self.monitor.next_deadline()
        t = self.reassembler.next_deadline()
        if t is not None and (best is None or t < best):
            best = t
        for due in self._hk_due.values():
            if due is not None and (best is None or due < best):
                best = due
        return best

    def bus_status(self, now):
        """Both buses' health as seen from this node, the active one marked."""
        window = self.monitor.window() or 2.0
        return [h.report(now, window, h.bus == self.monitor.active) for h in self.health]

    def switch_bus(self, now, bus=None, reason="command"):
        """Make bus (default: the other one) active, e.g. on the application's own judgement."""
        old = self.monitor.active
        new = (1 - old) if bus is None else bus
        if new == old:
            return False
        self.monitor._switch(new, now)
        self._emit(ev.BUS_SWITCHED, now, old=old, new=new, reason=reason)
        return True

    # -- application side ----------------------------------------------------------------------

    def set_value(self, key, value):
        """Set a parameter's current value by id or name (checked against its encoding)."""
        p = self.nodedef.parameter(key)
        if p is None:
            raise KeyError(key)
        enc.encode(p.encoding, value)
        p.value = value

    def get_value(self, key):
        p = self.nodedef.parameter(key)
        if p is None:
            raise KeyError(key)
        return p.value

    def send_raw(self, data, bus=None):
        """Raw data mode: one REP frame of up to 8 bytes."""
        if len(data) > 8:
            raise ValueError("raw frame data is at most 8 bytes, got %d" % len(data))
        self._tx(self.monitor.active if bus is None else bus, bytes(data))

    # -- services ------------------------------------------------------------------------------

    @micropython.native
    def _tx(self, bus, data):
        self._frames.append((bus, self._rep_id, data))
        self.health[bus].tx_frames += 1  # BusHealth.sent
        self.counters["tx"] += 1

    @micropython.native
    def _reply(self, bus, service, subtype, data=b""):
        if len(data) <= 4:  # one frame, [0][0][service][subtype][data], as split makes it
            self._tx(bus, bytes((0, 0, service, subtype)) + data)
            return
        for frame in split(bytes((service, subtype)) + data):
            self._tx(bus, frame)

    @micropython.native
    def _verification(self, bus, subtype, service, req_subtype):
        # verification reports depend on the bus and three small numbers only: each frame is
        # made once, then sent from the table, so answering a request allocates next to nothing
        key = (bus << 24) | (subtype << 16) | (service << 8) | req_subtype
        frame = self._canned.get(key)
        if frame is None:
            data = split(bytes((pk.SERVICE_VERIFICATION, subtype, service, req_subtype)))[0]
            frame = (bus, self._rep_id, data)
            if len(self._canned) < _CANNED_MAX:
                self._canned[key] = frame
        return frame

    @micropython.native
    def _verify(self, bus, subtype, service, req_subtype):
        frame = self._canned.get((bus << 24) | (subtype << 16) | (service << 8) | req_subtype)
        if frame is None:
            frame = self._verification(bus, subtype, service, req_subtype)
        self._frames.append(frame)
        self.health[bus].tx_frames += 1  # BusHealth.sent
        self.counters["tx"] += 1

    @micropython.native
    def _serve(self, packet, bus, now, start=0):
        # the packet is packet[start:] (a one-frame request is served in its frame's bytes)
        self.counters["requests"] += 1
        if len(packet) - start < 2:
            self.counters["rejected"] += 1
            self._emit(
                ev.REQUEST_REJECTED, now, service=None, subtype=None, reason="packet under 2 bytes"
            )
            return
        service = packet[start]
        subtype = packet[start + 1]
        key = (service << 8) | subtype
        if key == _PING_KEY:  # no data, nothing to decode: the replies are ready-made
            self._ping(bus, service, subtype, packet, now)
            return
        handler = self._handlers.get(key)
        try:
            if handler is None:
                raise _Reject("service (%d,%d) not supported" % (service, subtype))
            if key == _PARAM_REQUEST_KEY:  # reads its ids in place
                self._param_request(bus, service, subtype, packet, now, start + 2)
            else:
                handler(bus, service, subtype, packet[start + 2 :], now)
        except _Reject as e:
            self.counters["rejected"] += 1
            self._verify(bus, pk.ACCEPT_FAIL, service, subtype)
            self._emit(ev.REQUEST_REJECTED, now, service=service, subtype=subtype, reason=e.reason)
        except ValueError as e:
            self.counters["rejected"] += 1
            self._verify(bus, pk.ACCEPT_FAIL, service, subtype)
            self._emit(ev.REQUEST_REJECTED, now, service=service, subtype=subtype, reason=str(e))

    @micropython.native
    def _ping(self, bus, service, subtype, data, now):
        # (1,1), (17,2), (1,7): three frames made once per bus
        frames = self._ping_frames[bus]
        if frames is None:
            frames = (
                self._verification(bus, pk.ACCEPT_OK, service, subtype),
                (bus, self._rep_id, _PING_REPORT_FRAME),
                self._verification(bus, pk.COMPLETE_OK, service, subtype),
            )
            self._ping_frames[bus] = frames
        out = self._frames
        out.append(frames[0])
        out.append(frames[1])
        out.append(frames[2])
        self.health[bus].tx_frames += 3  # BusHealth.sent
        self.counters["tx"] += 3

    @micropython.native
    def _param_request(self, bus, service, subtype, data, now, start=0):
        # the request's data is data[start:]: [N][id x N]
        n = len(data)
        if n - start < 1 or data[start] != n - start - 1:
            pk.unpack_ids(data[start:])  # raises the error that says what is wrong
        first = start + 1  # the ids, read in place (no list of them)
        size = 3
        params = self.nodedef.parameters
        for i in range(first, n):
            p = params.get(data[i])
            if p is None:
                raise _Reject("unknown parameter %d" % data[i])
            size += 1 + p.size
        if size > MAX_PACKET_SIZE:
            raise _Reject("report of %d bytes exceeds %d" % (size, MAX_PACKET_SIZE))
        # the (20,2) packet, [20][2] and pk.pack_values of the current values, written in place
        # behind a frame's [0][0] (an integer in range packed as enc.encode packs it, anything
        # else by enc.encode, which also raises for a value that does not fit: rejected)
        buf = bytearray(size + 2)
        buf[2] = pk.SERVICE_PARAMETER
        buf[3] = pk.PARAM_REPORT
        buf[4] = n - first
        off = 5
        packs = enc.PACK
        for i in range(first, n):
            pid = data[i]
            p = params[pid]
            buf[off] = pid
            off += 1
            v = p.value
            packing = packs.get(p.encoding)
            if packing is not None and type(v) is int and packing[1] <= v <= packing[2]:
                struct.pack_into(packing[0], buf, off, v)
            else:
                b = enc.encode(p.encoding, v)
                buf[off : off + len(b)] = b
            off += p.size
        if size > 6:
            self._verify(bus, pk.ACCEPT_OK, service, subtype)
            self._reply(bus, pk.SERVICE_PARAMETER, pk.PARAM_REPORT, bytes(buf[4:]))
            self._verify(bus, pk.COMPLETE_OK, service, subtype)
            return
        # one frame, [0][0][20][2][report] as split makes it, between the two verification
        # reports from the table: three frames sent at once
        canned = self._canned
        key = (bus << 24) | (service << 8) | subtype
        accept = canned.get(key | (pk.ACCEPT_OK << 16))
        if accept is None:
            accept = self._verification(bus, pk.ACCEPT_OK, service, subtype)
        done = canned.get(key | (pk.COMPLETE_OK << 16))
        if done is None:
            done = self._verification(bus, pk.COMPLETE_OK, service, subtype)
        out = self._frames
        out.append(accept)
        out.append((bus, self._rep_id, bytes(buf)))
        out.append(done)
        self.health[bus].tx_frames += 3  # BusHealth.sent
        self.counters["tx"] += 3

    def _param_set(self, bus, service, subtype, data, now):
        values = dict(pk.unpack_values(self.nodedef, data))
        self._verify(bus, pk.ACCEPT_OK, service, subtype)
        ok = True
        if self.on_parameters_set is not None:
            try:
                ok = self.on_parameters_set(values) is not False
            except Exception:  # the application's failure is reported, never raised into the loop
                ok = False
        if ok:
            for pid in values:
                self.nodedef.parameters[pid].value = values[pid]
        self._emit(ev.PARAMETERS_SET, now, values=values, ok=ok)
        self._verify(bus, pk.COMPLETE_OK if ok else pk.COMPLETE_FAIL, service, subtype)

    def _report_ids(self, data):
        ids = pk.unpack_ids(data)
        if not ids:
            raise _Reject("no report ids")
        for rid in ids:
            if rid not in self.nodedef.reports:
                raise _Reject("unknown report %d" % rid)
        return ids

    def _hk_enable(self, bus, service, subtype, data, now):
        ids = self._report_ids(data)
        self._verify(bus, pk.ACCEPT_OK, service, subtype)
        for rid in ids:
            self.nodedef.reports[rid].enabled = True
            if rid not in self._hk_due:
                self._hk_due[rid] = now + self._interval(rid)
        self._emit(ev.HK_CHANGED, now, report_ids=ids, enabled=True)
        self._verify(bus, pk.COMPLETE_OK, service, subtype)

    def _hk_disable(self, bus, service, subtype, data, now):
        ids = self._report_ids(data)
        self._verify(bus, pk.ACCEPT_OK, service, subtype)
        for rid in ids:
            self.nodedef.reports[rid].enabled = False
            self._hk_due.pop(rid, None)
        self._emit(ev.HK_CHANGED, now, report_ids=ids, enabled=False)
        self._verify(bus, pk.COMPLETE_OK, service, subtype)

    def _hk_one_shot(self, bus, service, subtype, data, now):
        ids = self._report_ids(data)
        self._verify(bus, pk.ACCEPT_OK, service, subtype)
        for rid in ids:
            self._reply(bus, pk.SERVICE_HOUSEKEEPING, pk.HK_REPORT, pk.pack_hk(self.nodedef, rid))
        self._verify(bus, pk.COMPLETE_OK, service, subtype)

    def _function(self, bus, service, subtype, data, now):
        fid, args = pk.unpack_function(self.nodedef, data)
        self._verify(bus, pk.ACCEPT_OK, service, subtype)
        ok = True
        if self.on_function is not None:
            try:
                ok = self.on_function(fid, args) is not False
            except Exception:  # the application's failure is reported, never raised into the loop
                ok = False
        self._emit(ev.FUNCTION_CALL, now, function_id=fid, args=args, ok=ok)
        self._verify(bus, pk.COMPLETE_OK if ok else pk.COMPLETE_FAIL, service, subtype)

    def describe_bus(self):
        return bus_name(self.monitor.active)
