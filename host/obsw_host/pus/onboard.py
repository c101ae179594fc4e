"""The on-board PUS process on the host: the core application process on UDP 5000 + APID.

``Onboard(sdb)`` builds the application process with the services the spacecraft database
calls for (1, 3, 5, 8, 9, 11, 12, 17, 19, 20, 21, and 22 when the database names a
``position_scheduling`` parameter), a parameter pool and an event manager on an interaction
layer node, and serves TCs from UDP. TM goes to every ground client that sent a TC or
subscribed (``obsw_host.pus.tm_fanout``), and to ``tm_to`` if given; each TM is logged
(``obsw_host.pus.tm_log``). Packets that service 15 retrieves from a packet store go to
``playback_to[vc]`` (a UDP address per virtual channel: the frame processor's input for that
VC, ``FrameProcessorHost.vc_ports``), or out in real time when the store's VC has none.
``start()`` runs it on an asyncio loop in a thread (demo, tests); ``serve()`` runs it in the
calling thread until stopped (``obsw obc serve``).
"""

import asyncio
import os
import threading
import time

from obsw.il.clock import REAL_CLOCK
from obsw.il.node import Node
from obsw.pus.app import EVENT_CYCLE_OVERRUN, ApplicationProcess
from obsw.pus.events import EventManager
from obsw.pus.parameters import ParameterPool
from obsw.pus.services.s03_housekeeping import Housekeeping
from obsw.pus.services.s05_events import EventReporting
from obsw.pus.services.s08_functions import FunctionManagement, functions
from obsw.pus.services.s09_time import TimeManagement
from obsw.pus.services.s11_scheduling import TimeScheduling
from obsw.pus.services.s12_monitoring import OnBoardMonitoring
from obsw.pus.services.s17_test import ServiceTest
from obsw.pus.services.s19_event_action import EventAction
from obsw.pus.services.s20_parameters import ParameterManagement
from obsw.pus.services.s21_sequencing import RequestSequencing
from obsw.pus.services.s22_position_scheduling import PositionScheduling

from obsw_host.net import DEFAULT_HOST
from obsw_host.pus.tm_fanout import TmFanout
from obsw_host.pus.tm_log import TmLog

PORT_BASE = int(os.environ.get("OBSW_PORT_BASE", "5000"))  # another base for a second system
TAI_MINUS_UNIX = 378691200 + 37  # seconds from 1958-01-01 TAI to 1970-01-01 UTC, now


def port_for(apid):
    """The UDP port of an application process: 5000 + APID."""
    return PORT_BASE + apid


def tai_now():
    """On-board time: TAI seconds since 1958-01-01 from the host clock."""
    return time.time() + TAI_MINUS_UNIX


class _Protocol(asyncio.DatagramProtocol):
    def __init__(self, onboard):
        self.onboard = onboard

    def connection_made(self, transport):
        self.onboard._transport = transport

    def datagram_received(self, data, addr):
        self.onboard._received(data, addr)

    def error_received(self, exc):
        self.onboard.app.count("udp_errors")


class Onboard:
    """The PUS application process of ``sdb`` served on UDP (see the module text)."""

    def __init__(
        self,
        sdb,
        *,
        node=None,
        apid=None,
        host=DEFAULT_HOST,
        port=None,
        period=0.1,
        store=None,
        tm_to=None,
        playback_to=None,
        max_tasks=16,
        components=(),
        time_exponent=None,
        time_code="cuc",
    ):
        self.sdb = sdb
        self.apid = apid if apid is not None else sdb.apid("pus")
        self.host = host
        self.port = port_for(self.apid) if port is None else port
        self.period = period
        self.tm_to = tm_to
        self.playback_to = dict(playback_to or {})
        self.node = node if node is not None else Node("pus")
        self.address = None
        self.ground = None  # the sender of the last TC
        self.fanout = TmFanout([tm_to])
        self.tm_log = TmLog(sdb)
        self._transport = None
        self._loop = None
        self._thread = None
        self._stopping = None
        self._ready = threading.Event()
        self._error = None
        overrun = EVENT_CYCLE_OVERRUN
        try:
            overrun = sdb.event("pus.cycle_overrun").id
        except KeyError:
            pass
        self.app = ApplicationProcess(
            self.apid,
            self._send,
            REAL_CLOCK,
            time=tai_now,
            store=store,
            period=period,
            max_tasks=max_tasks,
            task_timeout=10.0,
            overrun_event=overrun,
        )
        self.tasks = []  # more coroutine functions to run on the process's loop
        self.providers = [self.node.provide(itf, impl) for itf, impl in components]
        self.pool = ParameterPool(sdb, self.node)
        self.events = EventManager(sdb, self.node)
        self.events.connect(self.app)
        self._own_parameters()
        self.pool.bind()
        self.events.bind()
        app = self.app
        if self.playback_to:
            app.playback = self._playback
        app.register(Housekeeping(self.pool, sdb.housekeeping))
        app.register(EventReporting(known=sdb.events))
        app.register(TimeManagement(time_exponent, time_code))
        app.register(ServiceTest())
        app.register(ParameterManagement(self.pool))
        app.register(FunctionManagement(functions(sdb), self.node))
        app.register(TimeScheduling())
        app.register(OnBoardMonitoring(self.pool, sdb.events))
        app.register(EventAction(known=sdb.events))
        app.register(RequestSequencing())
        if sdb.position_parameter is not None:
            app.register(PositionScheduling(self.pool, sdb.position_parameter.qualified))

    def _own_parameters(self):
        counters = self.app.counters
        for name, counter in (
            ("pus.tc_received", "received"),
            ("pus.tm_sent", "tm_sent"),
            ("pus.failed", "failed"),
        ):
            try:
                self.pool.provide(name, lambda c=counter: counters.get(c, 0))
            except KeyError:
                pass  # the database does not list this one

    # -------------------------------------------------------------------------- I/O

    def _send(self, raw):
        t = self._transport
        if t is None:
            raise OSError("not bound")
        self.tm_log.tm(raw)
        if not self.fanout.send(t.sendto, raw):
            self.app.count("tm_no_ground")

    def _playback(self, raw, vc):
        """The app's playback: a retrieved packet to the frame processor's ``vc`` input."""
        address = self.playback_to.get(vc)
        if address is None:
            self.app.count("playback_realtime")
            self._send(raw)
            return
        t = self._transport
        if t is None:
            raise OSError("not bound")
        t.sendto(raw, address)
        self.app.count("playback_sent")

    def _received(self, data, addr):
        if self.fanout.heard(data, addr):
            self.ground = addr
            self.app.receive(data)

    async def main(self):
        """Bind, then serve TCs and run the activity loop until ``stop()``."""
        loop = asyncio.get_running_loop()
        self._loop = loop
        self._stopping = asyncio.Event()
        try:
            transport, _ = await loop.create_datagram_endpoint(
                lambda: _Protocol(self), local_addr=(self.host, self.port)
            )
        except OSError as e:
            self._error = e
            self._ready.set()
            raise
        self.address = transport.get_extra_info("sockname")
        tasks = [asyncio.ensure_future(self.app.run(self.period))]
        if self.node is not None:
            tasks.append(asyncio.ensure_future(self.node.serve()))
        for make in self.tasks:
            tasks.append(asyncio.ensure_future(make()))
        self._ready.set()
        try:
            await self._stopping.wait()
        finally:
            for t in tasks:
                t.cancel()
            for t in tasks:
                try:
                    await t
                except asyncio.CancelledError:
                    pass
            for _, task in list(self.app.tasks):
                task.cancel()
            transport.close()
            self._transport = None

    def serve(self):
        """Serve in the calling thread until ``stop()`` (from another thread) or Ctrl-C."""
        asyncio.run(self.main())

    def start(self, timeout=5.0):
        """Serve on an asyncio loop in a daemon thread; returns once bound."""
        self._thread = threading.Thread(target=self._thread_main, name="pus-onboard", daemon=True)
        self._thread.start()
        if not self._ready.wait(timeout):
            raise TimeoutError("on-board PUS process did not start within %ss" % timeout)
        if self._error is not None:
            raise self._error
        return self

    def _thread_main(self):
        try:
            asyncio.run(self.main())
        except OSError:
            pass  # reported to start() through _error

    def call(self, fn, timeout=5.0):
        """Run ``fn()`` on the process's loop thread (where the core lives); return its value."""
        if self._loop is None:
            return fn()
        import concurrent.futures

        fut = concurrent.futures.Future()

        def run():
            try:
                fut.set_result(fn())
            except Exception as e:
                fut.set_exception(e)

        self._loop.call_soon_threadsafe(run)
        return fut.result(timeout)

    def stop(self, timeout=5.0):
        loop = self._loop
        if loop is not None and self._stopping is not None:
            try:
                loop.call_soon_threadsafe(self._stopping.set)
            except RuntimeError:
                pass  # the loop has already ended
        if self._thread is not None:
            self._thread.join(timeout)
            self._thread = None

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()
