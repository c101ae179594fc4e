"""Drive a core SpaceCAN controller or responder over two python-can buses (A and B).

One loop thread owns the state machine; one reader thread per bus only queues frames. Code on
other threads reaches the state machine through `call(fn)` (fn(now) runs in the loop thread).
Or the application owns the state machine: `start(loop=False)` starts the readers only and the
application's own loop calls `run_pending()` when `wake` says frames came (or when
`next_wait()` has passed); the OBC does this to serve the interaction layer in the same thread.
Interfaces: "socketcan" (Raspberry Pi, channels e.g. can0/can1), "virtual" and "udp_multicast"
(simulation; udp_multicast needs msgpack), or anything python-can knows.
"""

import collections
import queue
import threading
import time

from obsw.spacecan import events as ev
from obsw.spacecan.controller import Controller
from obsw.spacecan.ids import (
    FULL_MASK,
    FUNCTION_MASK,
    ID_HEARTBEAT,
    ID_REP,
    ID_SCET,
    ID_SYNC,
    ID_UTC,
)

_MAX_WAIT = 0.05  # longest the loop sleeps with nothing due, so stop() is prompt


# python-can's default udp_multicast port; bus B uses the next one
UDP_MULTICAST_PORT = 43113


class AdapterError(RuntimeError):
    """The loop is not running, or a call into it did not finish in time."""


def filters_for(node):
    """python-can receive filters: every REP id for a controller (or the master wrapping one),
    a responder's own ids."""
    if isinstance(getattr(node, "controller", node), Controller):
        return [{"can_id": ID_REP, "can_mask": FUNCTION_MASK, "extended": False}]
    ids = (ID_HEARTBEAT, ID_SYNC, ID_SCET, ID_UTC, node.req_id)
    return [{"can_id": i, "can_mask": FULL_MASK, "extended": False} for i in ids]


class BusFaults:
    """Fault injection shared by every adapter on the same pair of channels (tests, demo).

    kill(bus) cuts a bus for all adapters that share this object: frames they send on it
    vanish (optionally reported as transmit errors) and frames they would receive from it are
    discarded, so peers that do not use this adapter are cut off too.
    """

    def __init__(self):
        self.dead = [False, False]
        self.tx_errors = [False, False]
        self._drop = [0, 0]
        self._corrupt = [0, 0]
        self._lock = threading.Lock()
        self.counters = {"dropped": 0, "corrupted": 0}

    def kill(self, bus, tx_errors=False):
        self.dead[bus] = True
        self.tx_errors[bus] = tx_errors

    def revive(self, bus):
        self.dead[bus] = False

    def drop(self, bus, count=1):
        with self._lock:
            self._drop[bus] += count

    def corrupt(self, bus, count=1):
        with self._lock:
            self._corrupt[bus] += count

    def outgoing(self, bus, data):
        """Return data to send, None to lose it silently, or False for a transmit error."""
        if self.dead[bus]:
            self.counters["dropped"] += 1
            return False if self.tx_errors[bus] else None
        with self._lock:
            if self._drop[bus]:
                self._drop[bus] -= 1
                self.counters["dropped"] += 1
                return None
            if self._corrupt[bus] and len(data):
                self._corrupt[bus] -= 1
                self.counters["corrupted"] += 1
                return bytes((data[0] ^ 0xFF,)) + bytes(data[1:])
        return data

    def incoming(self, bus):
        return not self.dead[bus]


# the node's latest events kept in ``CanAdapter.events`` for whoever looks (tests, tools):
# the older ones go, so that an OBC running for months holds a fixed amount (each
# housekeeping report's event holds its values: 10,000 of them were megabytes)
KEEP_EVENTS = 256


class CanAdapter:
    """Moves frames between two python-can buses and one core node, and runs its deadlines."""

    def __init__(
        self,
        node,
        interface="virtual",
        channels=("spacecan_a", "spacecan_b"),
        buses=None,
        faults=None,
        clock=time.monotonic,
        bitrate=None,
        wake=None,
        **bus_kwargs,
    ):
        self.node = node
        self.clock = clock
        self.wake = wake  # called (from reader threads too) whenever something was queued
        self.faults = faults
        self.channels = tuple(channels)
        self._own_buses = buses is None
        if buses is None:
            import can  # lazily: python-can is only needed when the adapter is used

            if bitrate is not None:
                bus_kwargs["bitrate"] = bitrate
            buses = []
            for index, ch in enumerate(self.channels):
                kwargs = dict(bus_kwargs)
                if interface == "udp_multicast":
                    # Linux hands every group joined on a port to each socket bound to that
                    # port, so bus A and bus B need a port each to stay apart.
                    kwargs["port"] = kwargs.get("port", UDP_MULTICAST_PORT) + index
                buses.append(
                    can.Bus(
                        interface=interface, channel=ch, can_filters=filters_for(node), **kwargs
                    )
                )
        self.buses = list(buses)
        self.events = collections.deque((), KEEP_EVENTS)  # the latest; listeners get all
        self.counters = {"rx": 0, "tx": 0, "tx_errors": 0, "loop_errors": 0}
        self._listeners = []
        self._waiters = {}
        self._inbox = queue.Queue()
        self._stop = threading.Event()
        self._threads = []
        self._loop_thread = None
        self._driven = False
        self._driver = None
        self.last_error = None

    # -- life cycle ----------------------------------------------------------------------------

    def start(self, loop=True):
        """Start the reader threads and the loop thread (daemons; stop() ends them).

        With ``loop=False`` no loop thread is started: the node is started here and the
        caller's thread drives it with ``run_pending()`` (see the module text).
        """
        if self._loop_thread is not None or self._driven:
            return self
        self._stop.clear()
        for i, bus in enumerate(self.buses):
            t = threading.Thread(target=self._reader, args=(i, bus), daemon=True)
            t.start()
            self._threads.append(t)
        if loop:
            self._loop_thread = threading.Thread(target=self._loop, daemon=True)
            self._loop_thread.start()
        else:
            self._driven = True
            self._driver = threading.get_ident()
            self.node.start(self.clock())
            self._flush()
        return self

    def stop(self):
        self._stop.set()
        for t in self._threads + ([self._loop_thread] if self._loop_thread else []):
            t.join(2.0)
        self._threads = []
        self._loop_thread = None
        self._driven = False

    def close(self):
        """Stop and shut down the buses this adapter opened."""
        self.stop()
        if self._own_buses:
            for b in self.buses:
                b.shutdown()

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.close()

    # -- threads -------------------------------------------------------------------------------

    def _reader(self, index, bus):
        while not self._stop.is_set():
            try:
                msg = bus.recv(0.05)
            except Exception as e:  # a bus that fails to read is reported, the other goes on
                self.last_error = e
                self._stop.wait(0.05)
                continue
            if msg is None or msg.is_error_frame or msg.is_remote_frame or msg.is_extended_id:
                continue
            if self.faults is not None and not self.faults.incoming(index):
                continue
            self._inbox.put((index, msg.arbitration_id, bytes(msg.data)))
            if self.wake is not None:
                self.wake()

    def _loop(self):
        node = self.node
        node.start(self.clock())
        self._flush()
        while not self._stop.is_set():
            now = self.clock()
            due = node.next_deadline()
            wait = _MAX_WAIT if due is None else min(max(due - now, 0.0), _MAX_WAIT)
            try:
                item = self._inbox.get(timeout=wait) if wait > 0 else self._inbox.get_nowait()
            except queue.Empty:
                item = None
            try:
                while item is not None:
                    self._handle(item)
                    try:
                        item = self._inbox.get_nowait()
                    except queue.Empty:
                        item = None
                node.poll(self.clock())
                self._flush()
            except Exception as e:  # the loop must outlive any one bad frame or callback
                self.counters["loop_errors"] += 1
                self.last_error = e

    def run_pending(self):
        """Driven mode: handle the frames and calls queued so far, run what is due and send
        what the node produced; return how many items were handled. Never raises: errors are
        counted in ``loop_errors`` and kept in ``last_error``, as in the loop thread."""
        self._driver = threading.get_ident()
        n = 0
        try:
            while True:
                try:
                    item = self._inbox.get_nowait()
                except queue.Empty:
                    break
                n += 1
                self._handle(item)
            self.node.poll(self.clock())
            self._flush()
        except Exception as e:  # the driving loop must outlive any one bad frame or callback
            self.counters["loop_errors"] += 1
            self.last_error = e
        return n

    def flush(self):
        """Driven mode: send the frames the node has produced (e.g. after a new request)."""
        try:
            self._flush()
        except Exception as e:  # as in run_pending
            self.counters["loop_errors"] += 1
            self.last_error = e

    def next_wait(self, limit=_MAX_WAIT):
        """Seconds until the node's next deadline, at most ``limit`` (0 when items wait)."""
        if not self._inbox.empty():
            return 0.0
        due = self.node.next_deadline()
        if due is None:
            return limit
        return min(max(due - self.clock(), 0.0), limit)

    def _handle(self, item):
        if len(item) == 3:  # (bus, can_id, data); calls are 4-tuples
            self.counters["rx"] += 1
            self.node.receive(item[0], item[1], item[2], self.clock())
            return
        _, fn, box, done = item
        try:
            box.append((True, fn(self.clock())))
        except Exception as e:
            box.append((False, e))
        done.set()

    def _flush(self):
        node = self.node
        # sending can produce more frames (a transmit error may switch the bus and re-send)
        frames = node.take_frames()
        while frames:
            for bus, can_id, data in frames:
                self._send(bus, can_id, data)
            frames = node.take_frames()
        for e in node.take_events():
            self.events.append(e)
            if e.kind == ev.REQUEST_DONE:
                w = self._waiters.pop(id(e.request), None)
                if w is not None:
                    w.set()
            for fn in self._listeners:
                try:
                    fn(e)
                except Exception as exc:  # a listener's bug must not stop the bus
                    self.counters["loop_errors"] += 1
                    self.last_error = exc

    def _send(self, bus, can_id, data):
        import can

        if self.faults is not None:
            data = self.faults.outgoing(bus, data)
            if data is None:
                return
            if data is False:
                self.counters["tx_errors"] += 1
                self.node.tx_error(bus, self.clock())
                return
        msg = can.Message(arbitration_id=can_id, data=data, is_extended_id=False)
        try:
            self.buses[bus].send(msg)
            self.counters["tx"] += 1
        except can.CanError:
            self.counters["tx_errors"] += 1
            self.node.tx_error(bus, self.clock())

    # -- API for other threads -----------------------------------------------------------------

    def subscribe(self, fn):
        """Call fn(event) in the loop thread for every event of the node."""
        self._listeners.append(fn)

    def call(self, fn, timeout=5.0):
        """Run fn(now) in the loop thread (here if the loop is not running, or if this is the
        driving thread); return its value."""
        if self._loop_thread is None and (
            not self._driven or self._driver == threading.get_ident()
        ):
            result = fn(self.clock())
            if self._driven:
                self.flush()
            return result
        box = []
        done = threading.Event()
        self._inbox.put(("call", fn, box, done))
        if self.wake is not None:
            self.wake()
        if not done.wait(timeout):
            raise AdapterError("call into the SpaceCAN loop did not run within %.1f s" % timeout)
        ok, value = box[0]
        if not ok:
            raise value
        return value

    def request(self, fn, timeout=10.0):
        """Start a request with fn(now) -> Request in the loop thread and wait until it is done.

        Returns the Request (check .status, .result, .error). A silent node ends as status
        "timeout" after the controller's own timeouts and retries; `timeout` here only guards
        against a stopped loop.
        """
        done = threading.Event()

        def start(now):
            req = fn(now)
            if req.done:
                done.set()
            else:
                self._waiters[id(req)] = done
            return req

        req = self.call(start)
        if not done.wait(timeout):
            raise AdapterError("request %r not finished within %.1f s" % (req, timeout))
        return req

    def wait_for(self, predicate, timeout):
        """Block until predicate() is true (checked every few ms) or timeout; return its value."""
        end = time.monotonic() + timeout
        while True:
            v = predicate()
            if v or time.monotonic() >= end:
                return v
            self._stop.wait(0.005)
