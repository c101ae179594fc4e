"""The OBC's SpaceCAN side in one process: the master and the equipment components served on
the interaction layer, two python-can buses below, all driven by one thread.

    obc = ObcSpaceCan([Equipment("CpduN", 5, nodedef)], interface="socketcan",
                      channels=("can0", "can1"))
    obc.serve()     # other processes now call CpduN.set_state_bits through a proxy

The bus readers are threads that only queue frames and wake the loop through a pipe that the
interaction layer's socket transport polls with its own sockets, so one thread owns the
controller, the components and every socket: an IL request and a CAN frame are each handled
as soon as they come. Any wait in this process (``node.wait``) keeps the bus going.

Run it with ``obsw spacecan master`` or ``python -m obsw_host.spacecan.obc``; ``--simulate``
adds a simulated responder per equipment node on the same buses (virtual channels are shared
within one process only, so that is how a test or demo gets a node to talk to).
"""

import argparse
import os
import select
import signal
import sys

from obsw.il.interface import check_unique_ids
from obsw.il.node import Node
from obsw.reconfig.node import definition_dict
from obsw.spacecan.controller import Controller
from obsw.spacecan.equipment import Equipment
from obsw.spacecan.master import MASTER, SpaceCanMaster
from obsw.spacecan.nodedef import NodeDefinition
from obsw.spacecan.responder import Responder

from obsw_host.mission import ids as mission_ids
from obsw_host.spacecan.adapter import CanAdapter

# The reconfiguration module's CPDU as seen on SpaceCAN: the one definition the firmware also
# uses (``obsw.reconfig.node``; nominal controller node 10, redundant 11).


def cpdu_node():
    """The CPDU node definition (a fresh dict, the firmware's own)."""
    return definition_dict()


_IDLE_WAIT = 0.2  # longest a wait blocks with nothing due (stop() is seen this soon)


class _Waker:
    """A pipe the bus reader threads write to; the loop polls its read end."""

    def __init__(self):
        self._r, self._w = os.pipe()
        os.set_blocking(self._r, False)
        os.set_blocking(self._w, False)

    def fileno(self):
        return self._r

    def notify(self):
        try:
            os.write(self._w, b"\0")
        except (BlockingIOError, OSError):  # full: the loop is awake anyway; closed: stopping
            pass

    def on_readable(self):
        try:
            while os.read(self._r, 4096):
                pass
        except (BlockingIOError, OSError):
            pass

    def close(self):
        for fd in (self._r, self._w):
            try:
                os.close(fd)
            except OSError:
                pass


class _MasterWithAccess:
    """The bus node the adapter drives when device access runs too: every frame is shown to
    the device access component (the reports of its requests), then handed to the master."""

    def __init__(self, master, access):
        self.master = master
        self.access = access

    def receive(self, bus, can_id, data, now):
        self.access.observe(bus, can_id, data, now)
        self.master.receive(bus, can_id, data, now)

    def __getattr__(self, name):
        return getattr(self.master, name)


class ObcSpaceCan:
    """SpaceCanMaster and equipment components on IL ``node``, over two python-can buses.

    ``equipment`` are ``Equipment`` objects; their nodes are declared to the controller.
    ``transport=True`` serves the components to other processes through a
    ``SocketTransport`` on ``directory``; with False only this process uses them. ``buses``
    and ``faults`` go to the ``CanAdapter`` (tests, demo); controller settings as keywords.
    """

    def __init__(
        self,
        equipment=(),
        *,
        interface="virtual",
        channels=("can0", "can1"),
        directory=None,
        transport=True,
        node=None,
        controller=None,
        buses=None,
        faults=None,
        heartbeat_period=0.5,
        timeout=0.5,
        retries=2,
        policy=None,
        device_access=False,
    ):
        self.node = node if node is not None else Node("spacecan-master")
        self.interface = interface
        self.controller = controller or Controller(
            heartbeat_period=heartbeat_period, timeout=timeout, retries=retries, policy=policy
        )
        self.equipment = list(equipment)
        for eq in self.equipment:
            self.controller.add_node(eq.node_id, eq.nodedef)
        check_unique_ids([MASTER] + [eq.interface for eq in self.equipment])
        self.master = SpaceCanMaster(self.controller)
        self.access = None
        bus_node = self.master
        if device_access:  # PUS service 2's way to the equipment (packet mode)
            from obsw.spacecan.device_access import SpaceCanDeviceAccess

            self.access = SpaceCanDeviceAccess(self.controller, timeout=timeout * (retries + 1))
            bus_node = _MasterWithAccess(self.master, self.access)
        self._waker = _Waker()
        self.adapter = CanAdapter(
            bus_node,
            interface=interface,
            channels=channels,
            buses=buses,
            faults=faults,
            wake=self._waker.notify,
        )
        self.transport = None
        if transport:
            from obsw_host.il.transport import SocketTransport

            self.transport = t = SocketTransport(self.node, directory)
            # the waker joins the transport's poll set: one blocking wait covers both worlds
            t.add_reader(self._waker)
        self.node.provide(MASTER, self.master)
        if self.access is not None:
            from obsw.spacecan.device_access import DEVICE_ACCESS

            self.node.provide(DEVICE_ACCESS, self.access)
        for eq in self.equipment:
            eq.provide(self.node)
        self.node.wait = self.wait
        self.simulated = []
        self._stop = False
        self._closed = False
        self._started = False

    def __repr__(self):
        return "ObcSpaceCan(%s)" % ", ".join(
            [MASTER.name] + ["%s=node %d" % (e.name, e.node_id) for e in self.equipment]
        )

    @property
    def address(self):
        return self.transport.address if self.transport is not None else None

    # -- life cycle ----------------------------------------------------------------------------

    def start(self):
        if not self._started:
            self._started = True
            self.adapter.start(loop=False)
        return self

    def simulate(self, **responder_kw):
        """Start a simulated responder for every equipment node on the same buses (its own
        adapter thread). A function ``set_<parameter>`` with one argument sets that parameter;
        other functions succeed and change nothing."""
        kw = {"heartbeat_period": self.controller.heartbeat_period or 0.5}
        kw.update(responder_kw)
        for eq in self.equipment:
            resp = simulated_responder(eq.node_id, eq.nodedef.to_dict(), **kw)
            ad = CanAdapter(
                resp,
                interface=self.interface,
                channels=self.adapter.channels,
                faults=self.adapter.faults,
            ).start()
            self.simulated.append(ad)
        return self.simulated

    def stop(self):
        """Make ``serve`` return (from a signal handler, a callback or another thread)."""
        self._stop = True
        self._waker.notify()

    def close(self):
        if self._closed:
            return
        self._closed = True
        for ad in self.simulated:
            ad.close()
        if self.transport is not None:
            self.transport.remove_reader(self._waker)
            self.transport.close()
        self.adapter.close()
        self._waker.close()
        self.node.wait = self.node.clock.sleep

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.close()

    # -- running -------------------------------------------------------------------------------

    def wait(self, timeout):
        """Block up to ``timeout`` (and no longer than the bus's next deadline) for a request,
        a reply or a frame, then handle whatever came; the IL node's wait."""
        limit = _IDLE_WAIT if timeout is None else max(timeout, 0.0)
        t = self.adapter.next_wait(limit)
        if self.transport is not None:
            self.transport.wait(t)
        else:
            if t > 0:
                select.select([self._waker], [], [], t)
            self._waker.on_readable()
        self.pump()

    def pump(self):
        """Handle what is queued on both sides: IL requests, frames, deadlines, callbacks."""
        if self.access is not None:
            self.access.now = self.node.clock.now()
        self._poll_node()
        self.adapter.run_pending()
        self._poll_node()
        for eq in self.equipment:
            eq.check()
        self.adapter.flush()

    def _poll_node(self):
        for _ in range(8):  # an operation may queue a request for another local provider
            if not self.node.poll():
                return

    def serve(self, until=None, timeout=None):
        """Serve until ``stop()``, ``until()`` is true, or ``timeout`` seconds passed."""
        self.start()
        clock = self.node.clock
        deadline = None if timeout is None else clock.now() + timeout
        self._stop = False
        while not self._stop and not self._closed:
            if until is not None and until():
                return True
            left = _IDLE_WAIT
            if deadline is not None:
                left = min(left, deadline - clock.now())
                if left <= 0:
                    return False
            self.wait(left)
        return True


def simulated_responder(node_id, definition, **kw):
    """A ``Responder`` for node ``node_id`` with definition (a dict) that acts on functions
    ``set_<parameter>(value)`` by setting the parameter."""
    nodedef = NodeDefinition.from_dict(definition, node_id)
    resp = Responder(node_id, nodedef, **kw)

    def on_function(fid, args):
        f = nodedef.functions[fid]
        if f.name.startswith("set_") and len(args) == 1:
            p = nodedef.parameter(f.name[4:])
            if p is not None:
                resp.set_value(p.parameter_id, args[min(args)])
        return True

    resp.on_function = on_function
    return resp


def mission_equipment(ids):
    """The equipment components of the mission database's ``nodes``."""
    nodes = list(ids.sdb.nodes.values())
    if not nodes:
        raise ids.error("nodes", "none; expected the SpaceCAN equipment nodes (or --equipment)")
    return [
        Equipment(n.name, n.node_id, NodeDefinition.load(n.definition, n.node_id)) for n in nodes
    ]


def parse_equipment(spec):
    """``NAME:NODE_ID[:DEFINITION.json]`` -> ``Equipment`` (no file: the sample CPDU)."""
    parts = spec.split(":", 2)
    if len(parts) < 2 or not parts[1].isdigit():
        raise ValueError("equipment must be NAME:NODE_ID[:DEFINITION.json], got %r" % spec)
    node_id = int(parts[1])
    if len(parts) == 3:
        nodedef = NodeDefinition.load(parts[2], node_id)
    else:
        nodedef = NodeDefinition.from_dict(cpdu_node(), node_id)
    return Equipment(parts[0], node_id, nodedef)


def add_arguments(p):
    p.add_argument("--interface", default="virtual", help="socketcan, udp_multicast, virtual")
    p.add_argument("--channel-a", default="can0", help="bus A (nominal) channel")
    p.add_argument("--channel-b", default="can1", help="bus B (redundant) channel")
    p.add_argument(
        "--equipment",
        action="append",
        metavar="NAME:NODE_ID[:DEF.json]",
        help="an equipment component (repeatable; default: the mission database's nodes)",
    )
    mission_ids.add_arguments(p)
    p.add_argument("--dir", help="IL name directory (default $OBSW_IL_DIR or a temp dir)")
    p.add_argument("--heartbeat-period", type=float, default=0.5)
    p.add_argument("--timeout", type=float, default=0.5, help="request timeout per attempt, s")
    p.add_argument("--retries", type=int, default=2)
    p.add_argument("--simulate", action="store_true", help="simulated responder per node")
    p.add_argument("--duration", type=float, default=None, help="stop after this many s")
    p.add_argument("--quiet", action="store_true")


def run(args):
    """Serve the master and the equipment until SIGTERM/SIGINT or ``--duration``."""
    if args.equipment:
        equipment = [parse_equipment(s) for s in args.equipment]
    else:
        equipment = mission_equipment(mission_ids.from_args(args))
    obc = ObcSpaceCan(
        equipment,
        interface=args.interface,
        channels=(args.channel_a, args.channel_b),
        directory=args.dir,
        heartbeat_period=args.heartbeat_period,
        timeout=args.timeout,
        retries=args.retries,
    )

    def stop(signum, frame):
        obc.stop()

    signal.signal(signal.SIGTERM, stop)
    signal.signal(signal.SIGINT, stop)
    try:
        obc.start()
        if args.simulate:
            obc.simulate()
        if not args.quiet:
            print(
                "%s served by pid %d at %r on %s %s (A) / %s (B)%s"
                % (
                    ", ".join(
                        [MASTER.name] + ["%s (node %d)" % (e.name, e.node_id) for e in equipment]
                    ),
                    os.getpid(),
                    obc.address,
                    args.interface,
                    args.channel_a,
                    args.channel_b,
                    ", simulated nodes" if args.simulate else "",
                ),
                flush=True,
            )
        obc.serve(timeout=args.duration)
    finally:
        obc.close()
    return 0


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m obsw_host.spacecan.obc", description=__doc__)
    add_arguments(p)
    return run(p.parse_args(argv))


if __name__ == "__main__":
    sys.exit(main())
