"""The PUS and component units of an OBC process (``obsw_host.obc.registry`` names every unit
kind; the SpaceCAN and frame processor units have modules of their own), each built from the
topology (``obsw_host.obc.topology``) and its section of the mission configuration.

A unit is built as ``Unit(topology, process, out)`` and has ``start()``, ``stop()`` and
``alive()`` (False when its work has stopped moving: the platform manager then treats the
process as hung). ``PusUnit`` is the PUS application process with the services of its
service table (``obsw_host.pus.onboard.SERVICES``) and, in the same asyncio loop, the CFDP
entity (service 23's copies), the OBCP engine (service 18), the process's plug-in components
and its interaction-layer transport; the SpaceCAN master and the frame processor run in
threads of their own; ``ComponentUnit`` serves plug-in components in a process without PUS.
Everything meets on the interaction layer's name directory and on UDP.
"""

import asyncio
import os
import threading
import time

from obsw.cfdp.filestore import OsFilestore
from obsw.il.node import Node
from obsw.pluto.engine import provide as provide_engine
from obsw.store import Store

from obsw_host.cfdp.filestore import RootedFilestore
from obsw_host.il.transport import SocketTransport
from obsw_host.obc import monitoring
from obsw_host.obc.health import HostHealth, ObcHealth
from obsw_host.obc.module_link import ModuleLink
from obsw_host.obc.onboard_time import ONBOARD_TIME, OnboardTime
from obsw_host.obc.passes import PASSES, Passes
from obsw_host.obc.ticks import Ticks
from obsw_host.obc.topology import OBC_HEALTH, PLATFORM, PLATFORM_EVENTS
from obsw_host.pus.onboard import Onboard, tai_now
from obsw_host.update.component import SOFTWARE
from obsw_host.update.component import build as software_component

TASK_DEATHS = 5  # task deaths within TASK_WINDOW seconds that make the process unhealthy
TASK_WINDOW = 60.0


class PlatformEvents:
    """The PUS process's side of ``PLATFORM``: events raised on its application process."""

    def __init__(self, app, sdb, health=None):
        self.app = app
        self.sdb = sdb
        self.health = health

    def status(self, restarts, watchdog):
        if self.health is not None:
            self.health.status(restarts, watchdog)

    def report(self, event, process, pid):
        if event not in PLATFORM_EVENTS:
            raise ValueError("no platform event %r" % (event,))
        try:
            e = self.sdb.event("platform." + event)
        except KeyError:  # a database without this event: counted, not raised
            self.app.count("platform_events_unknown")
            return None
        return self.app.event(e.id, e.severity, e.pack({"process": process, "pid": pid}))


def space_link_timers(remote):
    """CFDP timers for a peer across the space link (contact awareness on): the round trip
    goes through COP-1 and the frames, behind the stores' dump, so the UDP values (1 s, ten
    tries, 60 s of inactivity) would give up within a pass; here 5 s, 30 tries, 30 minutes."""
    remote.ack_interval = max(remote.ack_interval, 5.0)
    remote.nak_interval = max(remote.nak_interval, 5.0)
    remote.check_interval = max(remote.check_interval, 5.0)
    remote.ack_limit = max(remote.ack_limit, 30)
    remote.nak_limit = max(remote.nak_limit, 30)
    remote.inactivity = max(remote.inactivity, 1800.0)


async def drive_transport(transport, node):
    """Serve a ``SocketTransport`` from an asyncio loop: its sockets wake the loop."""
    loop = asyncio.get_running_loop()
    wake = asyncio.Event()
    watched = set()
    try:
        while True:
            fds = transport.fds()  # the transport's poll set changes as peers come and go
            for fd in fds - watched:
                loop.add_reader(fd, wake.set)
            for fd in watched - fds:
                loop.remove_reader(fd)
            watched = fds
            try:
                await asyncio.wait_for(wake.wait(), transport.renew_interval)
            except asyncio.TimeoutError:
                pass
            wake.clear()
            transport.wait(0)
            node.poll()
    finally:
        for fd in watched:
            loop.remove_reader(fd)


def _components_alive(built):
    """False if a plug-in component that can say so says its work has stopped."""
    for _, impl in built:
        alive = getattr(impl, "alive", None)
        if alive is not None and not alive():
            return False
    return True


def _close_components(built):
    for _, impl in built:
        close = getattr(impl, "close", None)
        if close is not None:
            close()


class PusUnit:
    """The PUS application process, its services, CFDP, OBCP and the process's components."""

    def __init__(self, topology, process, out=print):
        config = topology.config
        self.config = config
        self.sdb = sdb = topology.sdb
        self.out = out
        opts = topology.section("pus")
        built = [(c, c.build()) for c in process.components]
        self.components = [b for _, b in built]
        self.ticks = Ticks(built, out)
        self.health = self._health(topology)
        self.components.append((OBC_HEALTH, self.health))
        self.onboard_time = OnboardTime(os.path.join(config.state, "onboard_time.json"), tai_now)
        self.components.append((ONBOARD_TIME, self.onboard_time))
        self.software = software_component(config, topology.section("update"))
        self.components.append((SOFTWARE, self.software))
        self.interfaces = topology.interfaces()
        self.ids = ids = topology.ids
        playback_to = None
        tm_to = None
        if topology.runs("frames"):
            tm_to = (config.host, ids.ports.tm)
            playback_to = {ids.playback_vc: (config.host, ids.ports.playback)}
        if opts.get("tm_to"):  # a fixed ground address besides the last TC's sender
            host, port = str(opts["tm_to"]).rsplit(":", 1)
            tm_to = (host, int(port))
        self.node = Node("obc-pus")
        self.transport = SocketTransport(self.node, config.il_directory)
        self.files = RootedFilestore(os.path.join(config.state, "files"))
        self.cfdp = None
        if "cfdp" in process.kinds:
            self._cfdp(topology.section("cfdp"))
        self.engine = None
        context = {"obc": True, "files": self.files, "options": dict(opts)}
        if "obcp" in process.kinds:
            obcp = topology.section("obcp")
            context.update(self._obcp(obcp))
            context["options"]["level"] = int(obcp["level"])
        self.onboard = Onboard(
            sdb,
            node=self.node,
            apid=ids.pus_apid,
            host=config.host,
            port=ids.ports.pus,
            config=ids.pus_config,
            period=float(opts["period"]),
            store=Store(os.path.join(config.state, "context")),
            tm_to=tm_to,
            playback_to=playback_to,
            components=self.components,
            context=context,
            time_code=opts["time_code"],  # ST[09] reports: "cuc" (9,2) or "cds" (9,3)
            time=self.onboard_time.now,
        )
        self.onboard.follow_period = float(opts["follow_period"])
        self.app = self.onboard.app
        self.obcp = self.app.services.get(18)
        self.node.provide(PLATFORM, PlatformEvents(self.app, sdb, self.health))
        self.passes = self._passes(topology)
        self.node.provide(PASSES, self.passes)
        self.software.refresh()  # update steps taken while this process was down: events
        self.module = None
        platform = topology.section("platform")
        if platform.get("module_uarts"):  # the UART link to the reconfiguration module
            self.module = ModuleLink(
                [config.resolve(d) for d in platform["module_uarts"]],
                self.app,
                self.onboard_time,
                self.engine,
                float(platform["context_period"]),
                out,
                timeout=float(platform["module_timeout"]),
            )
            self.module.restore()
        monitoring.install(self.app, sdb, opts["monitoring"])  # first start: the mission's
        self.app.unsent_listeners.append(self._unsent)
        self._reporting_unsent = False
        self._running = False

    # -------------------------------------------------------------------------- building

    def _health(self, topology):
        """The ``Obc`` health component (``obsw_host.obc.health``)."""
        opts = topology.section("platform")
        self.health_period = float(opts["health_period"])
        host = HostHealth(
            opts["health_root"], opts["disk"] or self.config.state, opts["thermal_zone"]
        )
        return ObcHealth(host)

    def _cfdp(self, opts):
        from obsw.cfdp.remote_copy import REMOTE_COPY, RemoteCopy
        from obsw.spp import TYPE_TM

        from obsw_host.cfdp.link import UdpEntity, make_entity

        ids = self.ids
        local, ground = ids.cfdp_entities
        peers = {}
        for eid, address in opts["peers"].items():
            host, port = address.rsplit(":", 1)
            peers[int(eid)] = (host, int(port))
        if not peers:  # the ground entity of the filestores, on its port of the mission
            peers[ground] = (self.config.host, ids.ports.cfdp_ground)
        # the entity's state beside the filestore, not in it: the ground cannot write there
        entity = make_entity(local, list(peers), self.files, state=self.config.state)
        self.cfdp = UdpEntity(
            entity,
            (self.config.host, ids.ports.cfdp),
            peers,
            apid=ids.apid("cfdp"),
            packet_type=TYPE_TM,
        )
        self.cfdp_poll = float(opts["poll"])
        self.copy = RemoteCopy(entity)
        self.node.provide(REMOTE_COPY, self.copy)
        self.cfdp.on_indication = self._indication
        entity.restore(time.monotonic())

    def _passes(self, topology):
        """Contact awareness (``obsw_host.obc.passes``): the pass table, the stores' dump,
        CFDP held across passes and its file data at the dump's rate (``share`` of the
        downlink rate: a sender paced by losses would flood the radio's queue first)."""
        from obsw_host.frames.coding import LinkSettings

        opts = topology.section("contact")
        bps = opts["downlink_bps"] or LinkSettings.of(self.config).downlink_bps or 9600
        passes = Passes(
            self.app.services.get(15),
            self.app.play,
            self.onboard_time.now,
            self.unit_event,
            stores=[int(s) for s in opts["stores"]],
            hold=float(opts["hold"]),
            bps=float(bps),
            share=float(opts["share"]),
            entity=self.cfdp.entity if self.cfdp is not None else None,
            path=os.path.join(self.config.state, "passes.json"),
        )
        if passes.enabled:
            self.app.tm_filters.append(passes.realtime)
            if self.cfdp is not None:  # files share the dump's part of the radio (spare)
                self.cfdp.rate = passes.spare
                self.cfdp.pace = False
                for r in self.cfdp.entity.mib.remotes.values():
                    space_link_timers(r)
        self.onboard.tc_listeners.append(passes.heard)
        return passes

    async def _passes_task(self):
        while self._running:
            self.passes.step()
            if self.cfdp is not None and self.passes.enabled:
                self.cfdp.rate = self.passes.spare  # the stores' backlog first, then files
            await asyncio.sleep(self.onboard.period)

    def _obcp(self, opts):
        """The OBCP engine; returns what service 18 takes from the context."""
        self.engine = provide_engine(
            self.node,
            self.sdb,
            self.interfaces,
            timeout=float(opts["timeout"]),
            activity_timeout=float(opts["activity_timeout"]),
            poll=0.05,
        )
        files = opts.get("files")
        self.step_period = float(opts["step_period"])
        return {
            "engine": self.engine,
            "procedures": OsFilestore(self.config.resolve(files)) if files else None,
        }

    # -------------------------------------------------------------------------- running

    async def _cfdp_task(self):
        # an error here ends the task: the loop's supervision reports it and restarts it
        while self._running:
            self.cfdp.step(0)
            self.copy.poll(time.monotonic())
            await asyncio.sleep(self.cfdp_poll)

    def _indication(self, ind):
        """CFDP indications: a state file set aside becomes an event, the rest go to the
        remote copy provider."""
        if ind.kind == "state_rejected":
            self.out("CFDP state file %s set aside: %s" % (ind.info["name"], ind.info["reason"]))
            self.unit_event("platform.state_rejected", {"unit": "cfdp/" + ind.info["name"]})
        self.copy.indication(ind)

    def unit_event(self, name, values):
        """Raise the database's event ``name`` (counted, not raised, if it has none)."""
        try:
            e = self.sdb.event(name)
        except KeyError:
            self.app.count("platform_events_unknown")
            return None
        return self.app.event(e.id, e.severity, e.pack(values))

    def _unsent(self, service, subtype, why):
        """A report that could not be built: a line in the log and ``pus.report_failed``."""
        self.out("TM[%d,%d] not sent: %s" % (service, subtype, why))
        if self._reporting_unsent:  # the event's own report failed: the line above says it
            return
        self._reporting_unsent = True
        try:
            values = {"service": service, "subtype": subtype, "reason": why[:200]}
            self.unit_event("pus.report_failed", values)
        finally:
            self._reporting_unsent = False

    def _task_died(self, name, why, restarts):
        self.out("task %s stopped (%s): restarted (%d)" % (name, why, restarts))
        n = min(restarts, 65535)
        self.unit_event("platform.task_restarted", {"task": name, "restarts": n})

    def _report_rejected(self):
        """Context store entries set aside at start: one event each, raised once."""
        store = self.app.store
        for name in getattr(store, "rejected", ())[self._rejected_reported :]:
            self.out("context state %s set aside (%s.bad): its unit starts clean" % (name, name))
            self.unit_event("platform.state_rejected", {"unit": "context/" + name})
        self._rejected_reported = len(getattr(store, "rejected", ()))

    _rejected_reported = 0

    async def _health_task(self):
        self._report_rejected()
        while self._running:
            self.health.sample()
            await asyncio.sleep(self.health_period)

    async def _engine_task(self):
        """Step the OBCP engine between the activity loop's cycles too: a procedure's next
        statement runs within ``step_period`` of its reply, not at the next cycle."""
        engine = self.engine
        while self._running:
            due = engine.next_deadline()
            now = time.time()
            if self.obcp.running and due is not None and due <= now:
                try:
                    engine.step(now)
                except Exception:
                    self.app.count("engine_errors")
            await asyncio.sleep(self.step_period)

    async def _transport_task(self):
        await drive_transport(self.transport, self.node)

    async def _ticks_task(self):
        await self.ticks.run(lambda: self._running)

    async def _module_task(self):
        await self.module.run(self.onboard.period, lambda: self._running)

    def start(self):
        self._running = True
        self.onboard.on_task_death = self._task_died
        self.onboard.tasks.append(self._transport_task)
        self.onboard.tasks.append(self._health_task)
        self.onboard.tasks.append(self._passes_task)
        if self.cfdp is not None:
            self.onboard.tasks.append(self._cfdp_task)
        if self.engine is not None:
            self.onboard.tasks.append(self._engine_task)
        if self.module is not None:
            self.onboard.tasks.append(self._module_task)
        if self.ticks:
            self.onboard.tasks.append(self._ticks_task)
        self.onboard.start()
        self.out(
            "PUS application process APID %d on udp %s:%d, services %s"
            % (
                self.onboard.apid,
                self.onboard.host,
                self.onboard.port,
                ",".join(str(s) for s in sorted(self.app.services)),
            )
        )
        if self.cfdp is not None:
            self.out("CFDP entity %d on udp %s:%d" % (
                self.cfdp.entity.mib.entity_id, *self.cfdp.address[:2]))  # fmt: skip
        return self

    def alive(self):
        last = self.app.last_cycle
        if last is None or time.monotonic() - last >= max(2.0, 20 * self.onboard.period):
            return False
        # a task that keeps dying is a crash loop: the platform manager restarts the process
        # (and counts it towards the power cycle) rather than this process spinning
        if self.onboard.deaths_within(TASK_WINDOW) >= TASK_DEATHS:
            return False
        return _components_alive(self.components)

    def stop(self):
        self._running = False
        self.onboard.stop()
        if self.module is not None:
            self.module.close()
        if self.cfdp is not None:
            self.cfdp.close()
        self.transport.close()
        _close_components(self.components)


class ComponentUnit:
    """The process's plug-in components, on a node of their own (a process without PUS)."""

    def __init__(self, topology, process, out=print):
        self.out = out
        self.node = Node("obc-%s-components" % process.name)
        self.transport = SocketTransport(self.node, topology.config.il_directory)
        built = [(c, c.build()) for c in process.components]
        self.components = [b for _, b in built]
        for itf, impl in self.components:
            self.node.provide(itf, impl)
        self.ticks = Ticks(built, out)
        self._thread = None
        self._running = False

    def _serve(self):
        """Requests and ticks, one at a time, on this unit's thread (the threading rule of
        ``obsw_host.obc.plugins``)."""
        self.ticks.serve(self.transport, self.node, lambda: self._running)

    def start(self):
        self._running = True
        self._thread = threading.Thread(target=self._serve, name="components")
        self._thread.daemon = True
        self._thread.start()
        self.out("components %s" % ", ".join(itf.name for itf, _ in self.components))
        return self

    def alive(self):
        if self._thread is None or not self._thread.is_alive():
            return False
        return _components_alive(self.components)

    def stop(self):
        self._running = False
        self.transport.stop()
        if self._thread is not None:
            self._thread.join(2.0)
        self.transport.close()
        _close_components(self.components)
