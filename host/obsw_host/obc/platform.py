"""The platform manager: starts the OBC's processes, watches them, restarts them.

Each process of the mission configuration runs as a child (``python -m obsw_host.obc CONFIG
--process NAME``). Every ``heartbeat`` seconds the manager calls each process's health
component (``Process_<name>.beat``) over the interaction layer. A process that has ended, or
whose heartbeat has failed for ``deadline`` seconds (``start_timeout`` for its first one), is
killed and started again at once. Starts, deaths and restarts become service 5 events
(``platform.started``, ``platform.died``, ``platform.restarted``: process index and pid),
raised through the PUS process's ``Platform`` component and kept until it can take them.

A process that dies before its first heartbeat is not a hardware fault but a mistake (its
configuration, a component module that does not import): one that refuses its configuration
(exit status 2) is stopped at once, one that dies ``crash_loop`` times in a row before its
first heartbeat is stopped then; either way one line says so and ``platform.stopped`` is
raised, and nothing is power-cycled. When every process is stopped, ``serve`` returns.
The processes run the software of the boot record's slot (``obsw_host.update``): with
``software``, the manager starts them from ``code`` (their ``sys.path``'s first folder) and
``obsw_host.update.trial.SoftwareWatch`` judges a version on trial and ends the run when the
boot record names another slot.
Failures of processes that ran healthy count towards the power cycle: after
``max_failures`` of them within ``window`` seconds the manager asks the reconfiguration
module to power-cycle the OBC: ``power_cycle(line, off_ms)`` of the CPDU node's equipment
component (``platform.power_cycle`` event first), once per window.
"""

import collections
import json
import os
import signal
import subprocess
import sys
import threading
import time

from obsw.il.errors import InteractionError
from obsw.il.node import Node

from obsw_host.il.transport import SocketTransport
from obsw_host.obc.supervision import Supervision
from obsw_host.obc.topology import PLATFORM, Topology

EXIT_REFUSED = 2  # a process's exit status when it refuses its configuration
STATUS_FILE = "platform.json"  # in the state folder: the processes as the manager sees them
_STARTING_BEAT = 0.05  # seconds between heartbeats until a process's first answer


def stop_on_signals():
    """An Event that SIGTERM and SIGINT set from now on."""
    done = threading.Event()

    def stop(signum, frame):
        done.set()

    signal.signal(signal.SIGTERM, stop)
    signal.signal(signal.SIGINT, stop)
    return done


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
        self.early_deaths = 0  # deaths in a row before a first heartbeat
        self.stopped = None  # why the manager stopped restarting it
        self.proxy = None

    @property
    def pid(self):
        return self.popen.pid if self.popen is not None else 0


class PlatformManager:
    """Supervises the processes of ``config`` (see the module text)."""

    def __init__(
        self,
        config,
        *,
        out=print,
        python=sys.executable,
        clock=time.monotonic,
        notifier=None,
        software=None,
        slot="factory",
        code=None,
        trial=False,
    ):
        topology = config if isinstance(config, Topology) else Topology(config)
        config = topology.config
        self.topology = topology
        self.config = config
        self.out = out
        self.python = python
        self.clock = clock
        self.settings = config.platform
        os.makedirs(config.il_directory, exist_ok=True)
        self.node = Node("platform")
        self.transport = SocketTransport(self.node, config.il_directory, listen=False)
        self.children = []
        for plan in topology.processes:
            c = Child(plan.name, plan.index)
            c.proxy = self.node.proxy(plan.health, timeout=0.5, retries=0)
            self.children.append(c)
        self.platform = self.node.proxy(PLATFORM, timeout=0.5, retries=0)
        self.failures = collections.deque()  # times of deaths and hangs
        self.pending = collections.deque((), 64)  # events not yet raised
        self.power_cycles = 0
        self.log = []  # (time, text)
        self._last_power_cycle = None
        self._stop = threading.Event()
        self.finished = threading.Event()  # set when every process is stopped
        self._thread = None
        self.supervision = Supervision(self, notifier)  # watchdog and systemd
        self._next_status = 0.0
        self.code = code  # the slot's lib folder, first on the processes' sys.path
        self.software = None
        if software is not None:
            from obsw_host.update.trial import SoftwareWatch

            self.software = SoftwareWatch(self, software, slot, trial)

    def say(self, text):
        self.log.append((self.clock(), text))
        self.out("[platform] " + text)
        self.write_status()

    # -------------------------------------------------------------------------- status

    def status(self, running=True):
        """What ``obsw obc status`` shows: the manager's pid and each process's pid, state,
        start (wall clock), restarts and components."""
        wall = time.time() - self.clock()
        plans = {p.name: p for p in self.topology.processes}
        out = []
        for c in self.children:
            state = "stopped" if c.stopped else ("up" if c.last_beat is not None else "starting")
            plan = plans.get(c.name)
            out.append({
                "name": c.name, "pid": c.pid, "state": state, "why": c.stopped,
                "started": wall + c.started if c.popen is not None else None,
                "restarts": c.restarts,
                "runs": list(plan.kinds) + [x.name for x in plan.components] if plan else [],
            })  # fmt: skip
        return {"manager": os.getpid(), "running": running, "written": time.time(),
                "mission": self.config.name, "processes": out}  # fmt: skip

    def write_status(self, running=True):
        """``STATUS_FILE`` in the state folder, replaced whole (a reader never sees half)."""
        path = os.path.join(self.config.state, STATUS_FILE)
        try:
            with open(path + ".new", "w") as f:
                json.dump(self.status(running), f)
            os.replace(path + ".new", path)
        except OSError:  # a full or read-only state folder: the log still says everything
            pass

    # -------------------------------------------------------------------------- processes

    def _spawn(self, child):
        cmd = [self.python, "-m", "obsw_host.obc", self.config.path, "--process", child.name]
        cmd += ["--state", self.config.state, "--il-dir", self.config.il_directory]
        cmd += ["--parent", str(os.getpid())]
        env = None
        if self.code is not None:
            path = os.environ.get("PYTHONPATH")
            env = dict(
                os.environ, PYTHONPATH=os.pathsep.join([self.code] + ([path] if path else []))
            )
        child.popen = subprocess.Popen(cmd, env=env)
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
        healthy = child.last_beat is not None
        status = child.popen.poll()
        if not healthy:
            child.early_deaths += 1
            limit = int(self.settings["crash_loop"])
            if status == EXIT_REFUSED or child.early_deaths >= limit:
                self._stop_child(child, why, status)
                return
        self.say("%s (pid %d) %s: restarting" % (child.name, child.pid, why))
        self._event("died", child)
        self._kill(child)
        self._spawn(child)
        child.restarts += 1
        self._event("restarted", child)
        if healthy:
            self._count_failure(child, now)

    def _stop_child(self, child, why, status):
        """A process that cannot start: stopped, with one line and one event."""
        self._kill(child)
        if status == EXIT_REFUSED:
            child.stopped = "refused its configuration (exit status 2)"
        else:
            child.stopped = "died %d times in a row before its first heartbeat (last: %s)" % (
                child.early_deaths, why)  # fmt: skip
        self.say("%s %s: stopped, not restarted (fix the mission, then start the OBC again)" % (
            child.name, child.stopped))  # fmt: skip
        self._event("stopped", child)
        if all(c.stopped for c in self.children):
            self.finished.set()

    def _count_failure(self, child, now):
        self.failures.append(now)
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
        self.say("%d failures within %ss: asking %s to power-cycle the OBC" % (
            len(self.failures), self.settings["window"], pc["component"]))  # fmt: skip
        try:
            itf = [i for i in self.topology.equipment_interfaces() if i.name == pc["component"]]
            if not itf:
                raise KeyError("no equipment %r in the configuration" % pc["component"])
            cpdu = self.node.proxy(itf[0], timeout=2.0, retries=1)
            cpdu.power_cycle(int(pc["line"]), int(pc["off_ms"])).result(5.0)
        except Exception as e:  # the request is best effort: the module's watchdog remains
            self.say("power-cycle request failed: %s" % e)

    # -------------------------------------------------------------------------- watching

    def step(self):
        """One round: check every child (ended? heartbeat?) and deliver pending events."""
        now = self.clock()
        period = float(self.settings["heartbeat"])
        for child in self.children:
            if child.stopped:
                continue
            if child.popen.poll() is not None:
                self._failed(child, "ended with status %s" % child.popen.returncode)
                continue
            if now < child.next_beat:
                continue
            child.next_beat = now + (period if child.last_beat is not None else _STARTING_BEAT)
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
                self.say("%s up (pid %d)" % (child.name, child.pid))
                self._event("started", child)
                child.early_deaths = 0
            child.last_beat = self.clock()
        self._flush_events()
        now = self.clock()
        self.supervision.step(now)
        if self.software is not None:
            self.software.step(now)
        if now >= self._next_status:
            self._next_status = now + float(self.settings["health_period"])
            self._send_status()
            self.write_status()

    def _send_status(self):
        """Restarts and watchdog state to the PUS process's ``Obc`` health component."""
        fresh = self.clock() - 2 * float(self.settings["heartbeat"])
        if not all(c.last_beat is not None and c.last_beat >= fresh for c in self.children
                   if not c.stopped):  # fmt: skip
            return  # a process is down or late: its heartbeat matters more than this figure
        r = self.supervision.report()
        try:
            self.platform.status(r["restarts"], r["watchdog"])
        except InteractionError:
            pass  # best effort: the next one follows

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
        self.supervision.stop()
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
        self.write_status(running=False)

    def serve(self, done=None):
        """Run until SIGTERM or SIGINT (True), until every process is stopped (False), or
        until the software watch ends the run (its outcome: ``restart``, ``rolled back: ..``).
        ``done``: an Event the caller's signal handlers set (``stop_on_signals``)."""
        done = done or stop_on_signals()
        watch = self.software
        self.start()
        try:
            while not done.wait(0.1):
                if self.finished.is_set() or (watch is not None and watch.outcome):
                    break
            else:
                return True
        finally:
            self.stop()  # the round in progress ends first: a trial's verdict is in
        return (watch.outcome if watch is not None else None) or False
