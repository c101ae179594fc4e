"""The components an OBC process runs, each built from its section of the mission configuration.

A unit has ``start()``, ``stop()`` and ``alive()`` (False when its work has stopped moving:
the platform manager then treats the process as hung). ``PusUnit`` is the PUS application
process with every service 1-23 and, in the same asyncio loop, the CFDP entity (service 23's
copies), the OBCP engine (service 18) and its interaction-layer transport; the SpaceCAN master
and the frame processor run in threads of their own; everything meets on the interaction
layer's name directory and on UDP.
"""

import asyncio
import os
import threading
import time

from obsw.il.node import Node

from obsw_host.il.transport import SocketTransport

PLAYBACK_PORT = 5000  # the frame processor's playback input (UDP 4999 + 1)


def equipment_interfaces(config):
    """The interfaces of the SpaceCAN equipment components the mission has."""
    from obsw.spacecan.equipment import equipment_interface

    return [equipment_interface(eq.name, eq.node_id, eq.nodedef) for eq in equipments(config)]


def equipments(config):
    """The SpaceCAN equipment: the configuration's ``spacecan.nodes`` if it lists any, else
    the spacecraft database's ``nodes``."""
    from obsw.pus.sdb import NodeDef
    from obsw.pus.sdb import load as load_sdb
    from obsw.spacecan.equipment import Equipment
    from obsw.spacecan.nodedef import NodeDefinition

    listed = config.section("spacecan").get("nodes")
    if listed:
        nodes = [
            NodeDef(n["name"], int(n["node_id"]), config.resolve(n["definition"])) for n in listed
        ]
    else:
        nodes = list(load_sdb(config.sdb_path).nodes.values())
    return [
        Equipment(n.name, n.node_id, NodeDefinition.load(n.definition, n.node_id)) for n in nodes
    ]


async def drive_transport(transport, node):
    """Serve a ``SocketTransport`` from an asyncio loop: its sockets wake the loop."""
    loop = asyncio.get_running_loop()
    wake = asyncio.Event()
    watched = set()
    try:
        while True:
            fds = set(transport._fds)  # the transport's poll set changes as peers come and go
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


class PusUnit:
    """The PUS application process with services 1-23, the CFDP entity and the OBCP engine."""

    def __init__(self, config, sdb, kinds, out=print):
        from obsw.store import Store

        from obsw_host.pus.onboard import Onboard

        self.config = config
        self.sdb = sdb
        self.out = out
        opts = config.section("pus")
        state = config.state
        components = []
        if "solar_panel" in kinds:
            from obsw_host.solar_panel import SOLAR_PANEL, SolarPanel

            components.append((SOLAR_PANEL, SolarPanel()))
        self.interfaces = [itf for itf, _ in components]
        if config.runs("solar_panel") and "solar_panel" not in kinds:
            from obsw_host.solar_panel import SOLAR_PANEL

            self.interfaces.append(SOLAR_PANEL)
        self.interfaces += equipment_interfaces(config) if config.runs("spacecan") else []
        playback_to = None
        tm_to = None
        if config.runs("frames"):
            f = config.section("frames")
            tm_port = int(f.get("tm_port", 4999))
            tm_to = (config.host, tm_port)
            playback_to = {int(f.get("playback_vc", 1)): (config.host, tm_port + 1)}
        if opts.get("tm_to"):  # a fixed ground address besides the last TC's sender
            host, port = str(opts["tm_to"]).rsplit(":", 1)
            tm_to = (host, int(port))
        self.node = Node("obc-pus")
        self.transport = SocketTransport(self.node, config.il_directory)
        self.onboard = Onboard(
            sdb,
            node=self.node,
            apid=opts.get("apid"),
            host=config.host,
            port=opts.get("port"),
            period=float(opts.get("period", 0.1)),
            store=Store(os.path.join(state, "context")),
            tm_to=tm_to,
            playback_to=playback_to,
            components=components,
        )
        self.app = self.onboard.app
        self.cfdp = None
        if "cfdp" in kinds:
            self._cfdp(config.section("cfdp"))
        self.engine = None
        if "obcp" in kinds:
            self._obcp(config.section("obcp"))
        self._storage(opts)
        self._services(opts)
        from obsw_host.obc.platform import PLATFORM, PlatformEvents

        self.node.provide(PLATFORM, PlatformEvents(self.app, sdb))
        self._running = False

    # -------------------------------------------------------------------------- building

    def _cfdp(self, opts):
        from obsw.cfdp.remote_copy import REMOTE_COPY, RemoteCopy
        from obsw.spp import TYPE_TM

        from obsw_host.cfdp.filestore import RootedFilestore
        from obsw_host.cfdp.link import UdpEntity, make_entity

        sdb = self.sdb
        self.files = RootedFilestore(os.path.join(self.config.state, "files"))
        local = sdb.filestore_entity(sdb.local_filestore)
        peers = {}
        for eid, address in opts.get("peers", {}).items():
            host, port = address.rsplit(":", 1)
            peers[int(eid)] = (host, int(port))
        entity = make_entity(local, list(peers), self.files)
        self.cfdp = UdpEntity(entity, (self.config.host, int(opts.get("port", 5100))), peers)
        self.cfdp.packet_type = TYPE_TM
        self.copy = RemoteCopy(entity)
        self.node.provide(REMOTE_COPY, self.copy)
        self.cfdp.on_indication = self.copy.indication
        entity.restore(time.monotonic())

    def _obcp(self, opts):
        from obsw.cfdp.filestore import OsFilestore
        from obsw.pluto.engine import provide
        from obsw.pus.services.s18_obcp import ObcpManagement

        self.engine = provide(
            self.node,
            self.sdb,
            self.interfaces,
            timeout=float(opts.get("timeout", 2.0)),
            activity_timeout=float(opts.get("activity_timeout", 30.0)),
            poll=0.05,
        )
        files = opts.get("files")
        fs = OsFilestore(self.config.resolve(files)) if files else None
        self.step_period = float(opts.get("step_period", 0.01))
        self.obcp = self.app.register(
            ObcpManagement(
                self.engine,
                filestore=fs,
                events=self.sdb.event,
                level=int(opts.get("level", 2)),
                clock=time.time,
            )
        )

    def _storage(self, opts):
        from obsw_host.cfdp.filestore import RootedFilestore

        if self.cfdp is None:
            self.files = RootedFilestore(os.path.join(self.config.state, "files"))

    def _services(self, opts):
        from obsw.pus.services.s02_device_access import DeviceAccess
        from obsw.pus.services.s04_statistics import ParameterStatistics
        from obsw.pus.services.s06_memory import MemoryManagement, areas_from_sdb
        from obsw.pus.services.s13_large_packets import LargePacketTransfer
        from obsw.pus.services.s14_forwarding import ForwardingControl
        from obsw.pus.services.s15_storage import Storage
        from obsw.pus.services.s23_files import FileManagement

        sdb = self.sdb
        app = self.app
        app.register(DeviceAccess(self.node, timeout=float(opts.get("device_timeout", 5.0))))
        app.register(ParameterStatistics(self.onboard.pool))
        app.register(MemoryManagement(areas_from_sdb(sdb, self.files)))
        app.register(LargePacketTransfer())
        app.register(ForwardingControl())
        app.register(Storage(filestore=self.files, rate=int(opts.get("playback_rate", 64))))
        app.register(
            FileManagement(
                self.files, sdb.filestores, sdb.local_filestore, self.node, poll_every=4
            )
        )

    # -------------------------------------------------------------------------- running

    async def _cfdp_task(self):
        while self._running:
            try:
                self.cfdp.step(0)
                self.copy.poll(time.monotonic())
            except OSError:
                return
            await asyncio.sleep(0.005)

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

    def start(self):
        self._running = True
        self.onboard.tasks.append(lambda: drive_transport(self.transport, self.node))
        if self.cfdp is not None:
            self.onboard.tasks.append(self._cfdp_task)
        if self.engine is not None:
            self.onboard.tasks.append(self._engine_task)
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
        return last is not None and time.monotonic() - last < max(2.0, 20 * self.onboard.period)

    def stop(self):
        self._running = False
        self.onboard.stop()
        if self.cfdp is not None:
            self.cfdp.close()
        self.transport.close()


class SpaceCanUnit:
    """The SpaceCAN master, the equipment components and device access, in their own thread."""

    def __init__(self, config, out=print):
        from obsw_host.spacecan.obc import ObcSpaceCan

        opts = config.section("spacecan")
        self.out = out
        self.opts = opts
        interface = opts.get("interface", "virtual")
        channels = tuple(opts.get("channels", ("can0", "can1")))
        buses = None
        if interface == "hub":  # the simulated reconfiguration module's CAN hub (UDP ports)
            from obsw_host.reconfig.canhub import HubBus

            buses = [HubBus(int(channels[0])), HubBus(int(channels[1]))]
        self.obc = ObcSpaceCan(
            equipments(config),
            interface=interface,
            channels=channels,
            buses=buses,
            directory=config.il_directory,
            heartbeat_period=float(opts.get("heartbeat_period", 0.5)),
            timeout=float(opts.get("timeout", 0.5)),
            retries=int(opts.get("retries", 2)),
            device_access=True,
        )
        self._thread = None

    def start(self):
        self.obc.start()
        if self.opts.get("simulate"):
            self.obc.simulate()
        self._thread = threading.Thread(target=self.obc.serve, name="spacecan", daemon=True)
        self._thread.start()
        self.out("%r on %s" % (self.obc, self.obc.interface))
        return self

    def alive(self):
        return self._thread is not None and self._thread.is_alive()

    def stop(self):
        self.obc.stop()
        if self._thread is not None:
            self._thread.join(2.0)
        self.obc.close()


class FramesUnit:
    """The frame processor on two UARTs (device paths, or ``pty``: a pseudo-terminal pair
    whose other end's path is written to ``STATE/uart_a`` and ``STATE/uart_b``); with
    ``keys`` (a key file) TC frames are authenticated."""

    def __init__(self, config, sdb, out=print):
        from obsw_host.frames.links import FdLink
        from obsw_host.frames.processor import FrameProcessorHost

        opts = config.section("frames")
        self.out = out
        links = []
        self.paths = {}
        for side in ("a", "b"):
            dev = opts.get("uart_" + side, "pty")
            if dev == "pty":
                controller, path = _pty()
                links.append(FdLink(controller, side.upper()))
                with open(os.path.join(config.state, "uart_" + side), "w") as f:
                    f.write(path + "\n")
                self.paths[side] = path
            else:
                links.append(config.resolve(dev) if dev.startswith(".") else dev)
                self.paths[side] = dev
        pus = config.section("pus")
        apid = int(pus.get("apid", sdb.apid("pus")))
        port = int(pus.get("port", 5000 + apid))
        tm_port = int(opts.get("tm_port", 4999))
        plan = sdb.tm_vcs
        security = {}
        from obsw_host.frames import policy

        key_path = policy.check(config)  # secure by default: keys, or "tc_security": "none"
        if key_path is None:
            out(policy.OFF_WARNING)
        else:  # TC (and TM, where the file has SAs for it) protected with SDLS
            from obsw_host.frames.processor import security_options

            state = os.path.join(config.state, "frames.keys.state")
            security = security_options(key_path, sdb, state)
        self.fp = FrameProcessorHost(
            links[0],
            links[1],
            int(opts.get("scid", 0x42)),
            host=config.host,
            port_base=port - apid,
            tm_port=tm_port,
            vc_ports={int(opts.get("playback_vc", 1)): tm_port + 1},
            tm_plan=plan,
            tm_frame_length=int(opts.get("tm_frame_length", 256)),
            clcw_period=float(opts.get("clcw_period", 0.5)),
            **security,
        )
        self.last_step = time.monotonic()
        self._stop = threading.Event()
        self._thread = None

    def _run(self):
        while not self._stop.is_set():
            self.fp.step(0.05)
            self.last_step = time.monotonic()

    def start(self):
        self._thread = threading.Thread(target=self._run, name="frames", daemon=True)
        self._thread.start()
        self.out(
            "frame processor: UART A %s, UART B %s, TM in on udp %d"
            % (self.paths["a"], self.paths["b"], self.fp.tm_port)
        )
        return self

    def alive(self):
        return self._thread is not None and time.monotonic() - self.last_step < 2.0

    def stop(self):
        self._stop.set()
        if self._thread is not None:
            self._thread.join(2.0)
        self.fp.close()


class ComponentUnit:
    """Sample equipment components served on their own node (when not with the PUS process)."""

    def __init__(self, config, kinds, out=print):
        self.node = Node("obc-components")
        self.transport = SocketTransport(self.node, config.il_directory)
        if "solar_panel" in kinds:
            from obsw_host.solar_panel import SOLAR_PANEL, SolarPanel

            self.node.provide(SOLAR_PANEL, SolarPanel())
        self._thread = None

    def start(self):
        self._thread = threading.Thread(target=self.transport.serve, name="components")
        self._thread.daemon = True
        self._thread.start()
        return self

    def alive(self):
        return self._thread is not None and self._thread.is_alive()

    def stop(self):
        self.transport.stop()
        if self._thread is not None:
            self._thread.join(2.0)
        self.transport.close()


def _pty():
    import tty

    controller, device = os.openpty()
    tty.setraw(device)
    path = os.ttyname(device)
    # the device end stays open here: with no one on it, the controller end would read EIO
    # (and be "readable") until the ground opens the path
    return controller, path
