"""One OBC process: the units the topology gives it, and its heartbeat.

``ObcProcess(config, name)`` builds the units of process ``name`` of the topology
(``obsw_host.obc.topology``; each unit's class from ``obsw_host.obc.registry``) and provides
``Process_<name>``, a small interaction-layer component whose ``beat()`` the platform manager
calls: it answers with the process id and a count while every unit's work moves, and fails
with ``HUNG`` naming the units that stopped.
"""

import os
import signal
import threading

from obsw.il.errors import ComponentError
from obsw.il.node import Node

from obsw_host.il.transport import SocketTransport
from obsw_host.obc.registry import unit_class
from obsw_host.obc.topology import Topology


class _Health:
    def __init__(self, units):
        self.units = units
        self.beats = 0

    def beat(self):
        stuck = [u for u, unit in self.units if not unit.alive()]
        if stuck:
            raise ComponentError("HUNG", "stopped: " + ", ".join(stuck), {"units": stuck})
        self.beats += 1
        return {"pid": os.getpid(), "beats": self.beats}


class ObcProcess:
    """The units of one process of ``config`` (see the module text); ``config`` may also be
    a ``Topology`` already built."""

    def __init__(self, config, name, out=print):
        topology = config if isinstance(config, Topology) else Topology(config)
        config = topology.config
        plan = topology.process(name)
        os.makedirs(config.state, exist_ok=True)
        os.makedirs(config.il_directory, exist_ok=True)
        self.topology = topology
        self.config = config
        self.name = name
        self.out = out
        self.units = [
            (label, unit_class(kind)(topology, plan, out)) for label, kind in plan.units()
        ]
        self.node = Node("obc-%s-health" % name)
        self.transport = SocketTransport(self.node, config.il_directory)
        self.health = _Health(self.units)
        self.node.provide(plan.health, self.health)
        self._thread = None

    @property
    def sdb(self):
        return self.topology.sdb

    def unit(self, name):
        for n, u in self.units:
            if n == name:
                return u
        return None

    def start(self):
        for _, unit in self.units:
            unit.start()
        self._thread = threading.Thread(target=self.transport.serve, name="health", daemon=True)
        self._thread.start()
        return self

    def serve(self, parent=None):
        """Run until SIGTERM or SIGINT (or until process ``parent`` is gone)."""
        done = threading.Event()

        def stop(signum, frame):
            done.set()

        signal.signal(signal.SIGTERM, stop)
        signal.signal(signal.SIGINT, stop)
        self.start()
        self.out("OBC process %r (pid %d) up: %s" % (
            self.name, os.getpid(), ", ".join(n for n, _ in self.units)))  # fmt: skip
        try:
            while not done.wait(0.5):
                if parent is not None and os.getppid() != parent:
                    break  # the platform manager is gone (killed, or its OBC powered off)
        finally:
            self.stop()

    def stop(self):
        self.transport.stop()
        if self._thread is not None:
            self._thread.join(2.0)
        for _, unit in reversed(self.units):
            unit.stop()
        self.transport.close()
