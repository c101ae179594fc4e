"""The on-board PUS process on the host: the core application process on UDP base + APID.

``Onboard(sdb)`` builds the application process with the services of ``SERVICES`` (the one
service table of the PUS process) whose needs are met: 1, 3, 5, 8, 9, 11, 12, 17, 19, 20, 21,
and 22 when the database names a ``position_scheduling`` parameter, and one ``MissionService``
per mission service (types 128..255) the database declares (``service_table``); the OBC's PUS
unit gives what the others need (``needs``: a filestore for 6, 15 and 23, the OBCP engine for
18, the OBC itself for 2, 4, 13 and 14). A parameter pool and an event manager on an interaction
layer node follow the components (also those that start later or restart), and TCs are
served from UDP. TM goes to every ground client that sent a TC or
subscribed (``obsw_host.pus.tm_fanout``), and to ``tm_to`` if given; each TM is logged
(``obsw_host.pus.tm_log``). Packets that service 15 retrieves from a packet store go to
``playback_to[vc]`` (a UDP address per virtual channel: the frame processor's input for that
VC, ``FrameProcessorHost.vc_ports``), or out in real time when the store's VC has none.
``start()`` runs it on an asyncio loop in a thread (demo, tests); ``serve()`` runs it in the
calling thread until stopped (``obsw obc serve``).
"""

import asyncio
import collections
import socket
import threading
import time

from obsw.il.clock import REAL_CLOCK
from obsw.il.node import Node
from obsw.pus.app import ApplicationProcess
from obsw.pus.config import from_sdb
from obsw.pus.events import EventManager
from obsw.pus.parameters import ParameterPool
from obsw.pus.services.mission import MissionService
from obsw.pus.services.s02_device_access import DeviceAccess
from obsw.pus.services.s03_housekeeping import Housekeeping
from obsw.pus.services.s04_statistics import ParameterStatistics
from obsw.pus.services.s05_events import EventReporting
from obsw.pus.services.s06_memory import MemoryManagement, areas_from_sdb
from obsw.pus.services.s08_functions import FunctionManagement, functions
from obsw.pus.services.s09_time import TimeManagement
from obsw.pus.services.s11_scheduling import TimeScheduling
from obsw.pus.services.s12_functional import FunctionalOnBoardMonitoring
from obsw.pus.services.s13_large_packets import LargePacketTransfer
from obsw.pus.services.s14_forwarding import ForwardingControl
from obsw.pus.services.s15_storage import Storage
from obsw.pus.services.s17_test import ServiceTest
from obsw.pus.services.s18_obcp import ObcpManagement
from obsw.pus.services.s19_event_action import EventAction
from obsw.pus.services.s20_parameters import ParameterManagement
from obsw.pus.services.s21_sequencing import RequestSequencing
from obsw.pus.services.s22_position_scheduling import PositionScheduling
from obsw.pus.services.s23_files import FileManagement

from obsw_host.mission.ids import EVENT_COPY_COMPLETED, EVENT_COPY_FAILED, EVENT_OVERRUN, event_id
from obsw_host.mission.ports import app_port
from obsw_host.net import DEFAULT_HOST
from obsw_host.pus.tai import TAI_MINUS_UNIX, tai_now  # noqa: F401 (names of this module too)
from obsw_host.pus.tm_fanout import TmFanout
from obsw_host.pus.tm_log import TmLog


def copy_events(sdb):
    """Service 23's copy events by name in the database (None: it declares them not)."""
    ids = (event_id(sdb, EVENT_COPY_COMPLETED), event_id(sdb, EVENT_COPY_FAILED))
    return None if None in ids else ids


class ServiceContext:
    """What the builders of ``SERVICES`` take: the process's database, pool, node and
    options, and what the OBC gives besides (``obc``, ``files``, ``engine``, ...)."""

    def __init__(self, sdb, pool, node, **extra):
        self.sdb = sdb
        self.pool = pool
        self.node = node
        self.position = sdb.position_parameter
        self.time_exponent = None
        self.time_code = "cuc"  # TM[9,2] (CUC) or TM[9,3] (CDS) time reports
        self.obc = None  # True in the OBC's PUS unit
        self.files = None  # the onboard filestore (services 6, 15, 23)
        self.engine = None  # the OBCP engine (service 18)
        self.procedures = None  # the filestore procedures are loaded from
        self.options = {}
        for k, v in extra.items():
            setattr(self, k, v)

    def option(self, key, default):
        return self.options.get(key, default)


# The service table of the PUS process: (service, needs, build(context)), in registration
# order; a service is built when every context attribute it needs is given (not None).
SERVICES = (
    (3, (), lambda c: Housekeeping(c.pool, c.sdb.housekeeping)),
    (5, (), lambda c: EventReporting(known=c.sdb.events)),
    (9, (), lambda c: TimeManagement(c.time_exponent, c.time_code)),
    (17, (), lambda c: ServiceTest()),
    (20, (), lambda c: ParameterManagement(c.pool)),
    (8, (), lambda c: FunctionManagement(functions(c.sdb), c.node)),
    (11, (), lambda c: TimeScheduling()),
    (12, (), lambda c: FunctionalOnBoardMonitoring(c.pool, c.sdb.events)),  # types 1-28
    (19, (), lambda c: EventAction(known=c.sdb.events)),
    (21, (), lambda c: RequestSequencing()),
    (22, ("position",), lambda c: PositionScheduling(c.pool, c.position.qualified)),
    (
        18,
        ("engine",),
        lambda c: ObcpManagement(
            c.engine,
            filestore=c.procedures,
            events=c.sdb.event,
            level=int(c.option("level", 2)),
            clock=time.time,
        ),
    ),  # fmt: skip
    (2, ("obc",), lambda c: DeviceAccess(c.node, timeout=float(c.option("device_timeout", 5)))),
    (4, ("obc",), lambda c: ParameterStatistics(c.pool)),
    (6, ("files",), lambda c: MemoryManagement(areas_from_sdb(c.sdb, c.files))),
    (13, ("obc",), lambda c: LargePacketTransfer()),
    (14, ("obc",), lambda c: ForwardingControl()),
    (
        15,
        ("files",),
        lambda c: Storage(filestore=c.files, rate=int(c.option("playback_rate", 64))),
    ),  # fmt: skip
    (
        23,
        ("files",),
        lambda c: FileManagement(
            c.files,
            c.sdb.filestores,
            c.sdb.local_filestore,
            c.node,
            poll_every=4,
            events=copy_events(c.sdb),
        ),
    ),  # fmt: skip
)


# -- mission services (types 128..255): one row of the table per service the database declares


def _mission_row(definition):
    timeout = lambda c: float(c.option("service_timeout", 5))  # noqa: E731
    return (definition.type, (), lambda c: MissionService(definition, c.node, timeout(c)))


def service_table(sdb, table=SERVICES):
    """The PUS process's service table: ``table`` (the standard's services) and a row for
    each mission service ``sdb`` declares (``obsw.pus.sdb_services``)."""
    return tuple(table) + tuple(_mission_row(d) for d in sdb.services.values())


UDP_MAX = 65536  # bytes: more than any UDP datagram carries (65,507 over IPv4)


def _bound(host, port):
    """A non-blocking UDP socket bound to ``host`` (a name, an IPv4 or an IPv6 address) and
    ``port``: the first address the name gives that binds, as asyncio's endpoints do."""
    error = None
    for family, kind, proto, _, address in socket.getaddrinfo(host, port, 0, socket.SOCK_DGRAM):
        sock = socket.socket(family, kind, proto)
        try:
            sock.setblocking(False)
            sock.bind(address)
            return sock
        except OSError as e:
            sock.close()
            error = e
    raise error or OSError("no address for %r" % host)


class _Udp:
    """The process's UDP socket on the event loop: datagrams read straight into one buffer
    (``loop.add_reader``), TM sent straight from the socket (issue 41: asyncio's datagram
    transport read each datagram into a fresh 256 KiB buffer, an mmap, an mremap and a munmap
    per TC, and its layers cost a TC round trip more than the work of its four reports). A
    datagram the socket cannot take now (its buffer full) waits in order for it to drain."""

    def __init__(self, loop, sock, received, count, unsent=None):
        self.loop = loop
        self.sock = sock
        self.received = received  # received(data, address)
        self.count = count  # count(counter name)
        self.unsent = unsent  # unsent(service, subtype, why) for a TM the socket refused
        self.buf = bytearray(UDP_MAX)
        self.view = memoryview(self.buf)
        self.waiting = collections.deque()  # (data, address) for the socket to take
        loop.add_reader(sock.fileno(), self._readable)

    def _readable(self):
        try:
            n, address = self.sock.recvfrom_into(self.buf)
        except (BlockingIOError, InterruptedError):
            return
        except OSError:  # an ICMP error for an earlier datagram (a ground gone)
            self.count("udp_errors")
            return
        self.received(bytes(self.view[:n]), address)

    def sendto(self, data, address):
        if not self.waiting:
            try:
                self.sock.sendto(data, address)
                return
            except (BlockingIOError, InterruptedError):
                self.loop.add_writer(self.sock.fileno(), self._writable)
            except OSError as e:
                self._refused(data, e)
                return
        self.waiting.append((bytes(data), address))

    def send_all(self, batch, targets):
        """Send every datagram of ``batch`` to every address of ``targets``, in order."""
        if self.waiting:
            for raw in batch:
                for address in targets:
                    self.sendto(raw, address)
            return
        sendto = self.sock.sendto
        for i, raw in enumerate(batch):
            for j, address in enumerate(targets):
                try:
                    sendto(raw, address)
                except OSError:  # the socket full or refusing: the careful way from here on
                    for k in range(j, len(targets)):
                        self.sendto(raw, targets[k])
                    for rest in batch[i + 1 :]:
                        for a in targets:
                            self.sendto(rest, a)
                    return

    def _refused(self, data, error):
        """A datagram the socket refused (too long, no route): counted and said."""
        self.count("udp_errors")
        if self.unsent is not None and len(data) > 8:  # TM[service, subtype]
            self.unsent(data[7], data[8], "UDP send of %d octets failed: %s" % (len(data), error))

    def _writable(self):
        while self.waiting:
            data, address = self.waiting[0]
            try:
                self.sock.sendto(data, address)
            except (BlockingIOError, InterruptedError):
                return
            except OSError as e:
                self._refused(data, e)
            self.waiting.popleft()
        self.loop.remove_writer(self.sock.fileno())

    def get_extra_info(self, name):
        return self.sock.getsockname() if name == "sockname" else None

    def close(self):
        self.loop.remove_reader(self.sock.fileno())
        if self.waiting:
            self.loop.remove_writer(self.sock.fileno())
        self.sock.close()


def task_name(make):
    """A task's name for reports: its function's name without underscores or ``_task``."""
    name = getattr(make, "task_name", None) or getattr(make, "__name__", "task")
    return name.strip("_").replace("_task", "") or "task"


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
        context=None,
        config=None,
        time=None,
    ):
        self.sdb = sdb
        self.apid = apid if apid is not None else sdb.apid("pus")
        self.host = host
        self.port = app_port(self.apid) if port is None else port
        self.period = period
        self.tm_to = tm_to
        self.playback_to = dict(playback_to or {})
        self.node = node if node is not None else Node("pus")
        self.address = None
        self.ground = None  # the sender of the last TC
        self.tc_listeners = []  # called with no argument for every TC received
        self.fanout = TmFanout([tm_to])
        self._batch = None  # the TM of the TC being handled, sent once it is (_flush)
        self.tm_log = TmLog(sdb)
        self._transport = None
        self._loop = None
        self._thread = None
        self._stopping = None
        self._ready = threading.Event()
        self._error = None
        overrun = event_id(sdb, EVENT_OVERRUN)  # None: the database declares none
        self.app = ApplicationProcess(
            self.apid,
            self._send,
            REAL_CLOCK,
            time=time or tai_now,  # onboard time: the OBC's corrected one, else the host's
            store=store,
            period=period,
            max_tasks=max_tasks,
            task_timeout=10.0,
            overrun_event=overrun,
            config=config if config is not None else from_sdb(sdb),
        )
        self.tasks = []  # more coroutine functions to run on the process's loop
        # supervision of every task of the loop (``_supervised``): a task that ends or raises
        # while the process runs is restarted after ``task_backoff`` s and reported through
        # ``on_task_death(name, why, restarts)``; ``task_deaths`` keeps when they died
        self.task_backoff = 0.2
        self.task_deaths = collections.deque((), 64)
        self.task_restarts = {}
        self.on_task_death = None
        self.providers = [self.node.provide(itf, impl) for itf, impl in components]
        self.pool = ParameterPool(sdb, self.node)
        if store is not None:  # values set through service 20 survive a restart
            self.pool.persist(store)
        self.events = EventManager(sdb, self.node)
        self.events.connect(self.app)
        self._own_parameters()
        self.pool.bind()
        self.events.bind()
        self.follow_period = 0.25  # seconds between looks for components that (re)appeared
        if self.playback_to:
            self.app.playback = self._playback
        self.context = ServiceContext(
            sdb, self.pool, self.node, time_exponent=time_exponent, time_code=time_code
        )
        for k, v in (context or {}).items():  # what the OBC gives the services besides
            setattr(self.context, k, v)
        self.register_services(self.context)

    def register_services(self, context, table=None):
        """Build and register every service of ``table`` (default: ``service_table``, the
        standard's and the mission's) whose needs ``context`` meets."""
        if table is None:
            table = service_table(context.sdb)
        for number, needs, build in table:
            if number in self.app.services:
                continue
            if all(getattr(context, n, None) is not None for n in needs):
                self.app.register(build(context))
        memory, parameters = self.app.services.get(6), self.app.services.get(20)
        if memory is not None and parameters is not None:
            parameters.use_memories(memory.areas)  # service 20 places parameters in them

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
        batch = self._batch
        if batch is not None:  # a TC being handled: its reports go out together, then logged
            batch.append(raw)
            return
        t = self._transport
        if t is None:
            raise OSError("not bound")
        self.tm_log.tm(raw)
        if not self.fanout.send(t.sendto, raw):
            self.app.count("tm_no_ground")

    def _flush(self, batch):
        """Send the TM a TC produced, back to back, once it is handled: each datagram wakes
        the ground, and a ground woken between two reports (the work of the next one still to
        do) took the CPU from this process on a loaded machine (issue 41)."""
        t = self._transport
        if t is None:
            self.app.count("tm_lost", len(batch))
            return
        targets = self.fanout.targets()
        if not targets:
            self.app.count("tm_no_ground", len(batch))
            return
        t.send_all(batch, targets)

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
            for heard in self.tc_listeners:
                heard()
            self._batch = batch = []
            try:
                self.app.receive(data)
            finally:
                self._batch = None
                if batch:
                    self._flush(batch)
                    log = self.tm_log.tm  # after the ground has its reports
                    for raw in batch:
                        log(raw)

    async def main(self):
        """Bind, then serve TCs and run the activity loop until ``stop()``."""
        loop = asyncio.get_running_loop()
        self._loop = loop
        self._stopping = asyncio.Event()
        try:
            sock = _bound(self.host, self.port)
        except OSError as e:
            self._error = e
            self._ready.set()
            raise
        transport = self._transport = _Udp(
            loop, sock, self._received, self.app.count, self.app.unsent
        )
        self.address = transport.get_extra_info("sockname")
        run = [("activity", lambda: self.app.run(self.period))]
        if self.node is not None:
            run.append(("il", self.node.serve))
            run.append(("parameters", lambda: self.pool.follow(self.follow_period)))
        for make in self.tasks:
            run.append((task_name(make), make))
        tasks = [asyncio.ensure_future(self._supervised(name, make)) for name, make in run]
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

    async def _supervised(self, name, make):
        """Run task ``make()`` until the process stops; restart it whenever it ends or raises
        before that: nothing on the loop dies silently."""
        while True:
            try:
                await make()
                why = "ended"
            except asyncio.CancelledError:
                raise
            except Exception as e:
                why = "%s: %s" % (type(e).__name__, e)
            if self._stopping.is_set():
                return
            n = self.task_restarts[name] = self.task_restarts.get(name, 0) + 1
            self.task_deaths.append((time.monotonic(), name))
            self.app.count("task_restarts")
            if self.on_task_death is not None:
                try:
                    self.on_task_death(name, why, n)
                except Exception:
                    self.app.count("task_report_errors")
            await asyncio.sleep(self.task_backoff)

    def deaths_within(self, seconds):
        """How many task deaths the last ``seconds`` saw (the unit's crash-loop guard)."""
        since = time.monotonic() - seconds
        return sum(1 for t, _ in self.task_deaths if t >= since)

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
