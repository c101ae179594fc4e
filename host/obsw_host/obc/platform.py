"""The platform manager: starts the OBC's processes, watches them, restarts them.

Each process of the mission configuration runs as a child (``python -m obsw_host.obc CONFIG
--process NAME``). Every ``heartbeat`` seconds the manager calls each process's health
component (``Process_<name>.beat``) over the interaction layer. A process that has ended, or
whose heartbeat has failed for ``deadline`` seconds (``start_timeout`` for its first one), is
killed and started again at once. Starts, deaths and restarts become service 5 events
(``platform.started``, ``platform.died``, ``platform.restarted``: process index and pid),
raised through the PUS process's ``Platform`` component and kept until it can take them.
After ``max_failures`` failures within ``window`` seconds the manager asks the
reconfiguration module to power-cycle the OBC: ``power_cycle(line, off_ms)`` of the CPDU
node's equipment component (``platform.power_cycle`` event first), once per window.
"""

import collections
import os
import subprocess
import sys
import threading
import time

from obsw.il.errors import InteractionError
from obsw.il.interface import Interface, Operation
from obsw.il.node import Node

from obsw_host.il.transport import SocketTransport

PLATFORM = Interface(
    "Platform",
    0x7EFF,
    [Operation("report", 1, ("event", "process", "pid"), description="raise a platform event")],
    description="the platform manager's events, raised by the PUS process",
)
EVENTS = ("started", "died", "restarted", "power_cycle")


class PlatformEvents:
    """The PUS process's side of ``PLATFORM``: events raised on its application process."""

    def __init__(self, app, sdb):
        self.app = app
        self.sdb = sdb

    def report(self, event, process, pid):
        if event not in EVENTS:
            raise ValueError("no platform event %r" % (event,))
        e = self.sdb.event("platform." + event)
        return self.app.event(e.id, e.severity, e.pack({"process": process, "pid": pid}))


class Child:
    """One supervised process."""

    def __init__(self, name, index):
        self.name = name
        self.index = index
        self.popen = None
        self.started = 0.0
        self.last_beat = None
        self.next_beat = 0.0
        self.restarts = 0
        self.proxy = None

    @property
    def pid(self):
        return self.popen.pid if self.popen is not None else 0


class PlatformManager:
    """Supervises the processes of ``config`` (see the module text)."""

    def __init__(self, config, *, out=print, python=sys.executable, clock=time.monotonic):
        from obsw_host.obc.assembly import health_interface

        self.config = config
        self.out = out
        self.python = python
        self.clock = clock
        self.settings = config.platform
        os.makedirs(config.il_directory, exist_ok=True)
        self.node = Node("platform")
        self.transport = SocketTransport(self.node, config.il_directory, listen=False)
        self.children = []
        for i, name in enumerate(config.processes):
            c = Child(name, i)
            c.proxy = self.node.proxy(health_interface(config, name), timeout=0.5, retries=0)
            self.children.append(c)
        self.platform = self.node.proxy(PLATFORM, timeout=0.5, retries=0)
        self.failures = collections.deque()  # times of deaths and hangs
        self.pending = collections.deque((), 64)  # events not yet raised
        self.power_cycles = 0
        self.log = []  # (time, text)
        self._last_power_cycle = None
        self._stop = threading.Event()
        self._thread = None

    def _say(self, text):
        self.log.append((self.clock(), text))
        self.out("[platform] " + text)

    # -------------------------------------------------------------------------- processes

    def _spawn(self, child):
        cmd = [self.python, "-m", "obsw_host.obc", self.config.path, "--process", child.name]
        cmd += ["--state", self.config.state, "--il-dir", self.config.il_directory]
        cmd += ["--parent", str(os.getpid())]
        child.popen = subprocess.Popen(cmd)
        child.started = self.clock()
        child.last_beat = None
        child.next_beat = child.started

    def _kill(self, child):
        p = child.popen
        if p is not None and p.poll() is None:
            p.kill()
            try:
                p.wait(5.0)
            except subprocess.TimeoutExpired:
                pass

    def _event(self, event, child):
        self.pending.append((event, child.index, child.pid))

    def _flush_events(self):
        while self.pending:
            event, index, pid = self.pending[0]
            try:
                self.platform.report(event, index, pid)
            except InteractionError:
                return  # the PUS process is not there (yet): keep them
            self.pending.popleft()

    def _failed(self, child, why):
        now = self.clock()
        self._say("%s (pid %d) %s: restarting" % (child.name, child.pid, why))
        self._event("died", child)
        self._kill(child)
        self.failures.append(now)
        self._spawn(child)
        child.restarts += 1
        self._event("restarted", child)
        window = float(self.settings["window"])
        while self.failures and now - self.failures[0] > window:
            self.failures.popleft()
        if len(self.failures) >= int(self.settings["max_failures"]):
            last = self._last_power_cycle
            if last is None or now - last > window:
                self._last_power_cycle = now
                self._power_cycle(child)

    def _power_cycle(self, child):
        pc = self.settings["power_cycle"]
        self._event("power_cycle", child)
        self._flush_events()
        self.power_cycles += 1
        self._say("%d failures within %ss: asking %s to power-cycle the OBC" % (
            len(self.failures), self.settings["window"], pc["component"]))  # fmt: skip
        try:
            from obsw_host.obc.units import equipment_interfaces

            itf = [i for i in equipment_interfaces(self.config) if i.name == pc["component"]]
            if not itf:
                raise KeyError("no equipment %r in the configuration" % pc["component"])
            cpdu = self.node.proxy(itf[0], timeout=2.0, retries=1)
            cpdu.power_cycle(int(pc["line"]), int(pc["off_ms"])).result(5.0)
        except Exception as e:  # the request is best effort: the module's watchdog remains
            self._say("power-cycle request failed: %s" % e)

    # -------------------------------------------------------------------------- watching

    def step(self):
        """One round: check every child (ended? heartbeat?) and deliver pending events."""
        now = self.clock()
        period = float(self.settings["heartbeat"])
        for child in self.children:
            if child.popen.poll() is not None:
                self._failed(child, "ended with status %s" % child.popen.returncode)
                continue
            if now < child.next_beat:
                continue
            child.next_beat = now + period
            try:
                child.proxy.beat()
            except InteractionError:
                limit = (
                    float(self.settings["start_timeout"])
                    if child.last_beat is None
                    else float(self.settings["deadline"])
                )
                since = child.started if child.last_beat is None else child.last_beat
                if self.clock() - since > limit:
                    self._failed(child, "silent for %.1f s" % (self.clock() - since))
                continue
            if child.last_beat is None:
                self._say("%s up (pid %d)" % (child.name, child.pid))
                self._event("started", child)
            child.last_beat = self.clock()
        self._flush_events()

    def start(self):
        for child in self.children:
            self._spawn(child)
        self._thread = threading.Thread(target=self._run, name="platform", daemon=True)
        self._thread.start()
        return self

    def _run(self):
        while not self._stop.is_set():
            self.step()
            self._stop.wait(0.05)

    def child(self, name):
        for c in self.children:
            if c.name == name:
                return c
        raise KeyError(name)

    def up(self):
        """True when every child has answered a heartbeat since its last start."""
        return all(c.last_beat is not None for c in self.children)

    def stop(self):
        self._stop.set()
        if self._thread is not None:
            self._thread.join(5.0)
        for child in self.children:
            p = child.popen
            if p is not None and p.poll() is None:
                p.terminate()
        for child in self.children:
            p = child.popen
            if p is not None:
                try:
                    p.wait(5.0)
                except subprocess.TimeoutExpired:
                    p.kill()
                    p.wait(5.0)
        self.transport.close()

    def serve(self):
        """Run until SIGTERM or SIGINT."""
        import signal

        done = threading.Event()

        def stop(signum, frame):
            done.set()

        signal.signal(signal.SIGTERM, stop)
        signal.signal(signal.SIGINT, stop)
        self.start()
        try:
            while not done.wait(0.5):
                pass
        finally:
            self.stop()
