"""One OBC process: the components the mission configuration gives it, and its heartbeat.

``ObcProcess(config, name)`` builds the units of process ``name`` (``obsw_host.obc.units``)
and provides ``Process_<name>``, a small interaction-layer component whose ``beat()`` the
platform manager calls: it answers with the process id and a count while every unit's work
moves, and fails with ``HUNG`` naming the units that stopped.
"""

import os
import threading

from obsw.il.errors import ComponentError
from obsw.il.interface import Interface, Operation
from obsw.il.node import Node

from obsw_host.il.transport import SocketTransport
from obsw_host.obc.units import ComponentUnit, FramesUnit, PusUnit, SpaceCanUnit

HEALTH_BASE = 0x7F00  # interface ids of the processes' health components: base + index


def health_interface(config, name):
    """The interface of process ``name``'s health component."""
    index = list(config.processes).index(name)
    return Interface(
        "Process_" + name,
        HEALTH_BASE + index,
        [Operation("beat", 1, (), description="pid and beats; HUNG if stuck")],
        description="heartbeat of OBC process %s" % name,
    )


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
    """The units of one process of ``config`` (see the module text)."""

    def __init__(self, config, name, out=print):
        from obsw.pus import sdb as sdb_module

        if name not in config.processes:
            raise KeyError("no process %r in %s" % (name, config.path))
        os.makedirs(config.state, exist_ok=True)
        os.makedirs(config.il_directory, exist_ok=True)
        self.config = config
        self.name = name
        self.out = out
        kinds = config.processes[name]
        self.sdb = sdb_module.load(config.sdb_path)
        self.units = []
        if "pus" in kinds:
            self.units.append(("pus", PusUnit(config, self.sdb, kinds, out)))
        elif config.plugins(kinds):
            self.units.append(("components", ComponentUnit(config, kinds, out)))
        if "spacecan" in kinds:
            self.units.append(("spacecan", SpaceCanUnit(config, out)))
        if "frames" in kinds:
            self.units.append(("frames", FramesUnit(config, self.sdb, out)))
        self.node = Node("obc-" + name)
        self.transport = SocketTransport(self.node, config.il_directory)
        self.health = _Health(self.units)
        self.node.provide(health_interface(config, name), self.health)
        self._thread = None

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
        import signal

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
