"""The PUS application process: TC bytes in, verification and service TM bytes out.

``receive(data)`` decodes a TC, checks it and routes it by service type to a registered
provider (``obsw.pus.services``). Nothing a TC carries can make it raise: a bad packet
becomes a service 1 failure report with the failure code and a counter, or, when not even
its header is readable, a counted drop. The TC's acknowledgement flags decide which success
reports go out. The TM a TC causes while it is handled carry one time, that of the first.
A handler that is a coroutine runs as an asyncio task, so slow requests (calls through the
interaction layer) proceed side by side; a bounded number may run at once. ``tick()`` is
one cycle of the activity loop that drives the services' periodic work; a service still
busy with its previous cycle is stopped and an overrun event raised.

Wiring is declared here and services add themselves to it; none replaces another's
attributes, so the order of ``register`` calls carries no meaning:
- the TM pipeline: every packed TM is offered to each of ``tm_stores`` (``store(header, raw,
  time)``, e.g. service 15's packet stores), then asked of each of ``tm_filters``
  (``forwards(header)`` -> bool, e.g. service 14); it goes out in real time unless a filter
  says no. All stages see every packet whatever the others decide. ``play(raw, vc)`` sends a
  retrieved packet to ``playback`` (set by the host to the frame processor's input of that
  virtual channel), or out in real time when there is none.
- events: ``event()`` calls every ``event_reporters`` entry (service 5: the report to the
  ground), then every ``event_listeners`` entry (service 19, a platform manager, ...), each
  as ``listener(event_id, severity, aux)``.

Sans-I/O: TM bytes go to ``out`` (a callable, or anything with ``put``, e.g. an
``obsw.il.queue.Queue``); time comes from ``clock.now()``; ``run()`` is the only coroutine
that sleeps, and it is optional.
"""

import asyncio

from obsw.compat import const
from obsw.il.interface import MEDIUM
from obsw.pus.config import DEFAULT
from obsw.pus.messages import (
    FAILURE_ILLEGAL_APID,
    FAILURE_ILLEGAL_SERVICE_TYPE,
    FAILURE_ILLEGAL_SUBTYPE,
)
from obsw.pus.packets import (
    ACK_ACCEPTANCE,
    ACK_COMPLETION,
    ACK_PROGRESS,
    ACK_START,
    PusError,
    RequestId,
    failure_code,
)
from obsw.pus.services.report_types import TmHeader
from obsw.pus.services.s01_verification import (
    ACCEPTANCE,
    COMPLETION,
    FAILURE_BUSY,
    FAILURE_EXECUTION,
    FAILURE_TIMEOUT,
    PROGRESS,
    START,
    PusFailure,
    Verification,
    app_data_error,
)
from obsw.pus.tc import PusTc
from obsw.pus.tm import PusTm
from obsw.spp import SEQ_UNSEGMENTED, SequenceCounter

# The event this process raises when periodic work overruns its cycle; the host gives the id
# the spacecraft database names ``pus.cycle_overrun`` (``overrun_event``; None: no event).
EVENT_CYCLE_OVERRUN = const(0xFF01)

_DECODE_ERRORS = (ValueError, KeyError, IndexError, TypeError)


class Request:
    """One TC being processed: its stage and the reports it has caused.

    Handlers call ``decode(layout)`` (which accepts the request once its application data
    decodes), then ``start()``, ``progress(step)``, ``report(...)`` for response TM, and raise
    ``PusFailure`` to fail at the current stage. Whatever a handler leaves out is done when
    it returns: the request is accepted, started and completed in that order.
    """

    __slots__ = ("app", "tc", "stage", "rid", "since")

    def __init__(self, app, tc, rid=None):
        self.app = app
        self.tc = tc
        self.stage = 0  # the last stage passed
        # the request ID, packed (the TC's first four octets): each service 1 report has it
        self.rid = bytes(rid) if rid is not None else tc.request_id().pack()
        self.since = 0.0

    @property
    def request_id(self):
        return RequestId.unpack(self.rid)

    @property
    def data(self):
        return self.tc.data

    @property
    def source(self):
        return self.tc.source_id

    def decode(self, layout):
        """``layout.unpack(data)``; undecodable data fails acceptance (illegal app data)."""
        try:
            value = layout.unpack(self.tc.data)
        except _DECODE_ERRORS as e:
            raise app_data_error(e) from None
        self.accept()
        return value

    def accept(self):
        if self.stage < ACCEPTANCE:
            self.stage = ACCEPTANCE
            self.app.count("accepted")
            if self.tc.ack & ACK_ACCEPTANCE:
                self.app.verification.succeeded(self.rid, ACCEPTANCE, self.tc.source_id)

    def start(self):
        if self.stage < START:
            self.accept()
            self.stage = START
            if self.tc.ack & ACK_START:
                self.app.verification.succeeded(self.rid, START, self.tc.source_id)

    def progress(self, step):
        self.start()
        if self.tc.ack & ACK_PROGRESS:
            self.app.verification.succeeded(self.rid, PROGRESS, self.tc.source_id, step)

    def report(self, message_type, data=b""):
        """Send a response TM (to the requester), after the start of execution."""
        self.start()
        return self.app.send_tm(message_type[0], message_type[1], data, self.tc.source_id)

    def complete(self):
        if self.stage < COMPLETION:
            self.start()
            self.stage = COMPLETION
            self.app.count("completed")
            if self.tc.ack & ACK_COMPLETION:
                self.app.verification.succeeded(self.rid, COMPLETION, self.tc.source_id)

    def fail(self, failure):
        """Report ``failure`` (a PusFailure) at the stage the request has reached."""
        if self.stage >= COMPLETION:
            return
        if self.stage < ACCEPTANCE:
            stage = ACCEPTANCE
            self.app.count("rejected")
        elif self.stage < START:
            stage = START
        elif failure.step is not None:
            stage = PROGRESS
        else:
            stage = COMPLETION
        self.stage = COMPLETION
        self.app.count("failed")
        self.app.count_failure(failure.code)
        self.app.verification.failed(
            self.rid, stage, failure.code, failure.data, self.tc.source_id, failure.step
        )


class ApplicationProcess:
    """One PUS application process (see the module text).

    ``apid`` is the process's own APID (its TM carry it); ``apids`` the TC APIDs it serves
    (default just ``apid``). ``time`` returns on-board time in seconds of the TM time code's
    epoch (default ``clock.now``). ``store`` is an ``obsw.store.Store`` for service context.
    """

    def __init__(
        self,
        apid,
        out,
        clock,
        *,
        config=DEFAULT,
        time=None,
        store=None,
        apids=None,
        max_tasks=16,
        task_timeout=None,
        period=None,
        overrun_event=EVENT_CYCLE_OVERRUN,
    ):
        self.apid = apid
        self.apids = tuple(apids) if apids else (apid,)
        self.clock = clock
        self.config = config
        self.time = time if time is not None else clock.now
        self.time_ref = 0  # spacecraft time reference status in TM headers
        self.store = store
        self.max_tasks = max_tasks
        self.task_timeout = task_timeout
        self.period = period  # the cycle of the activity loop, seconds
        self.overrun_event = overrun_event
        self.out = out.put if hasattr(out, "put") else out
        self.tm_stores = []  # store(header, raw, time) for every TM
        self.tm_filters = []  # forwards(header) -> False withholds a TM from real time
        self.playback = None  # callable(raw, vc) for TM retrieved from packet stores
        self.event_reporters = []  # callable(event_id, severity, aux) -> True if reported
        self.event_listeners = []  # callable(event_id, severity, aux), after the reporters
        self.unsent_listeners = []  # callable(service, subtype, why) for a TM not sent
        self.services = {}
        self.sequence = SequenceCounter()
        self.message_counters = {}  # (service << 8 | subtype) -> next message type counter
        self.tc_counts = {}  # (service << 8 | subtype) -> TCs received of that type
        self.counters = {}
        self.failures = {}  # failure code -> count
        self.tasks = []  # [request, task] of handlers running as asyncio tasks
        self.events_lost = 0
        self.last_cycle = None
        self._stamping = False  # a TC is being handled (``receive``)
        self._stamp = None  # the time code of its reports, once the first is made
        self._tm = PusTm(apid, 0, 0, seq_flags=SEQ_UNSEGMENTED)
        self.verification = Verification()
        self.register(self.verification)

    # -------------------------------------------------------------------------- set-up

    def register(self, service):
        """Add a service provider; it takes over its service type."""
        self.services[service.SERVICE] = service
        service.attach(self)
        return service

    def count(self, name, n=1):
        self.counters[name] = self.counters.get(name, 0) + n

    def count_failure(self, code):
        self.failures[code] = self.failures.get(code, 0) + 1

    # -------------------------------------------------------------------------- telecommands

    def receive(self, data):
        """Process one TC packet (bytes); never raises because of what ``data`` holds."""
        self.count("received")
        try:
            tc = PusTc.unpack(data, self.config)
        except PusError as e:
            self._reject_packet(e)
            return None
        except Exception:  # a decoder defect must not stop the process either
            self.count("dropped")
            return None
        req = Request(self, tc, data[:4])  # a decoded TC's first 4 octets: its request ID
        if tc.apid not in self.apids:
            req.fail(PusFailure(FAILURE_ILLEGAL_APID))
            return req
        service = self.services.get(tc.service)
        if service is None:
            req.fail(PusFailure(FAILURE_ILLEGAL_SERVICE_TYPE))
            return req
        handler = service.handler(tc.subtype)
        if handler is None:
            req.fail(PusFailure(FAILURE_ILLEGAL_SUBTYPE))
            return req
        key = (tc.service << 8) | tc.subtype  # only served types: the table stays bounded
        self.tc_counts[key] = self.tc_counts.get(key, 0) + 1
        if len(self.tasks) >= self.max_tasks:
            req.fail(PusFailure(FAILURE_BUSY))
            return req
        self._stamping = True  # the reports made while it is handled carry one time
        try:
            self._run(req, handler)
        finally:
            self._stamping = False
            self._stamp = None
        return req

    def _reject_packet(self, error):
        if error.packet_id is None:
            self.count("dropped")  # not even a header to name the request by
            return
        self.count("rejected")
        self.count("failed")
        code = failure_code(error)
        self.count_failure(code)
        rid = RequestId.from_words(error.packet_id, error.sequence_control)
        self.verification.failure(rid, ACCEPTANCE, code)

    def _run(self, req, handler):
        try:
            result = handler(req)
        except PusFailure as f:
            req.fail(f)
            return
        except Exception as e:
            self.count("handler_errors")
            req.fail(PusFailure(FAILURE_EXECUTION, str(e)))
            return
        if result is not None and hasattr(result, "send"):
            req.since = self.clock.now()
            coro = self._finish(req, result)
            try:
                task = asyncio.create_task(coro)
            except RuntimeError:  # CPython with no event loop running
                coro.close()
                result.close()
                req.fail(PusFailure(FAILURE_EXECUTION, "no event loop for an async handler"))
                return
            self.tasks.append([req, task])
            return
        req.complete()

    async def _finish(self, req, coro):
        try:
            await coro
            req.complete()
        except PusFailure as f:
            req.fail(f)
        except asyncio.CancelledError:
            req.fail(PusFailure(FAILURE_TIMEOUT))
        except Exception as e:
            self.count("handler_errors")
            req.fail(PusFailure(FAILURE_EXECUTION, str(e)))
        finally:
            for i, entry in enumerate(self.tasks):
                if entry[0] is req:
                    del self.tasks[i]
                    break

    async def idle(self):
        """Wait until every running handler task has finished."""
        while self.tasks:
            await self.tasks[0][1]

    # -------------------------------------------------------------------------- telemetry

    def send_tm(self, service, subtype, data=b"", destination=0, apid=None):
        """Pack and send one TM; returns the packet bytes (None if it could not be sent)."""
        if apid is None:
            apid = self.apid
        key = (service << 8) | subtype
        counters = self.message_counters
        n = counters.get(key, 0)
        config = self.config
        seq = self.sequence
        count = seq.next(apid)
        try:
            t = self._stamp
            if t is None and config.time is not None:
                t = config.time.from_seconds(self.time())
                if self._stamping:  # the TC being handled: its other reports reuse it
                    self._stamp = t
            tm = self._tm  # one packet object, its fields set for each TM (no allocation)
            tm.apid = apid
            tm.service = service
            tm.subtype = subtype
            tm.data = data
            tm.seq_count = count
            tm.message_counter = n
            tm.destination_id = destination
            tm.time = t
            tm.time_ref = self.time_ref
            tm.config = config
            raw = tm.pack()
        except ValueError as e:  # counts advance only for packets sent: no gap on the ground
            seq.set(apid, count)
            self.count("tm_unpackable")
            self.unsent(service, subtype, str(e))
            return None
        except Exception:
            seq.set(apid, count)
            raise
        counters[key] = (n + 1) & config.message_counter_max
        if self.tm_stores or self.tm_filters:
            if not self._pipeline(raw):
                self.count("tm_withheld")
                return raw
        try:
            self.out(raw)
        except Exception as e:
            self._lost(raw, e)
            return None
        counters = self.counters
        counters["tm_sent"] = counters.get("tm_sent", 0) + 1
        return raw

    def _pipeline(self, raw):
        """Offer ``raw`` to every store, ask every filter; True if it goes out in real time."""
        try:
            h = TmHeader(raw, self.config)
        except ValueError:
            self.count("tm_malformed")
            return True
        t = self.time()
        for store in self.tm_stores:
            store(h, raw, t)
        keep = True
        for forwards in self.tm_filters:
            if not forwards(h):
                keep = False
        return keep

    def _emit(self, raw):
        try:
            self.out(raw)
        except Exception as e:
            self._lost(raw, e)
            return False
        return True

    def _lost(self, raw, error):
        """The output's failure is counted and said; the loop goes on."""
        self.count("tm_lost")
        if len(raw) > 8:  # TM[service, subtype] from the secondary header
            self.unsent(raw[7], raw[8], "output failed: %s" % (error,))

    def play(self, raw, vc):
        """Send a TM retrieved from a packet store on virtual channel ``vc``."""
        play = self.playback
        if play is None:
            return self._emit(raw)
        try:
            play(raw, vc)
        except Exception:
            self.count("tm_lost")
            return False
        return True

    def unsent(self, service, subtype, why):
        """A TM[service, subtype] that could not be built: each of ``unsent_listeners`` hears
        why (the host raises an event and logs it); never raises."""
        for fn in self.unsent_listeners:
            try:
                fn(service, subtype, why)
            except Exception:
                self.count("listener_errors")

    def event(self, event_id, severity, aux=b""):
        """Raise an on-board event: reporters first, then listeners; True if it was reported."""
        reported = False
        if not self.event_reporters:
            self.events_lost += 1
        for report in self.event_reporters:
            if report(event_id, severity, aux):
                reported = True
        for listener in self.event_listeners:
            try:
                listener(event_id, severity, aux)
            except Exception:
                self.count("listener_errors")
        return reported

    # -------------------------------------------------------------------------- activity loop

    def tick(self):
        """One cycle: start every service's periodic work, stop overruns and stale tasks.

        Returns the number of overruns found in this cycle.
        """
        clock = self.clock
        now = clock.now()
        overruns = 0
        for svc in self.services.values():
            if svc.cyclic is None:
                continue
            prev = svc._cycle_task
            if prev is not None:
                svc._cycle_task = None
                if not prev.done():
                    prev.cancel()
                    overruns += 1
                    self._overrun(svc.SERVICE)
            try:
                r = svc.cyclic(now)
            except Exception:
                self.count("cyclic_errors")
                continue
            if r is not None and hasattr(r, "send"):
                coro = self._guard(r)
                try:
                    svc._cycle_task = asyncio.create_task(coro)
                except RuntimeError:
                    coro.close()
                    r.close()
                    self.count("cyclic_errors")
        if self.task_timeout is not None:
            for req, task in self.tasks:
                if now - req.since > self.task_timeout and not task.done():
                    task.cancel()
        if self.period is not None:
            spent = clock.now() - now
            if spent > self.period:
                overruns += 1
                self._overrun(0)
        self.last_cycle = now
        return overruns

    async def _guard(self, coro):
        try:
            await coro
        except asyncio.CancelledError:
            pass
        except Exception:
            self.count("cyclic_errors")

    def _overrun(self, service):
        self.count("overruns")
        if self.overrun_event is not None:  # None: the mission declares no such event
            self.event(self.overrun_event, MEDIUM, bytes((service,)))

    async def run(self, period=None, cycles=None):
        """The activity loop: ``tick`` every ``period`` seconds (``cycles`` times, or forever)."""
        if period is not None:
            self.period = period
        period = self.period if self.period is not None else 1.0
        clock = self.clock
        deadline = clock.now()
        n = 0
        while cycles is None or n < cycles:
            self.tick()
            n += 1
            deadline += period
            delay = deadline - clock.now()
            if delay < 0:  # the loop itself fell behind: count it and start afresh
                self.count("late_cycles")
                deadline = clock.now()
                delay = 0
            await asyncio.sleep(delay)

    def status(self):
        """Counters as a dict (for housekeeping and the ground's 'obsw ground status')."""
        out = dict(self.counters)
        out["running"] = len(self.tasks)
        out["failures"] = dict(self.failures)
        return out
