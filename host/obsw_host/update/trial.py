"""The platform manager's side of updates: the boot record watched, a new version's trial judged.

``SoftwareWatch(manager, software, slot, trial)`` runs in every round of the platform manager
(``obsw_host.obc.platform``), which started its processes from ``slot``:

- On trial, the version is confirmed once every process has answered its heartbeats for
  ``update.healthy_after`` seconds and ``Software.self_test`` (in the PUS process: the
  version's files against their signed hashes, and the mission's own test) passes. It is
  rolled back, and the manager restarts the processes from the version before, when
  ``update.deadline`` seconds pass without that, when the self-test fails, or when a process
  is stopped for good (it cannot start: it crashes at once, or refuses its configuration).
- Whatever the trial, a boot record that now names another slot to run (the ground
  activated a staged version, or rolled back) ends the manager's run with ``restart``, a
  second after the change, so the TC's completion report leaves first.

``obsw obc serve`` then starts a new platform manager from what ``Software.choose`` says.
"""

import os

from obsw.il.errors import ComponentError, InteractionError

from obsw_host.update.component import SOFTWARE

_LOOK_PERIOD = 0.5  # seconds between looks at the boot record
_RESTART_DELAY = 1.0  # seconds from a boot record change to the restart


class SoftwareWatch:
    def __init__(self, manager, software, slot, trial):
        self.manager = manager
        self.software = software
        self.slot = slot
        self.trial = trial
        self.settings = manager.topology.section("update")
        self.proxy = manager.node.proxy(SOFTWARE, timeout=2.0, retries=0)
        self.started = manager.clock()
        self.healthy_since = None
        self.outcome = None  # "restart" or "rolled back: why", once the run must end
        self._next_look = 0.0
        self._restart_at = None
        self._mtime = self._stamp()

    def _stamp(self):
        try:
            return os.stat(self.software.path).st_mtime_ns
        except OSError:
            return None

    def step(self, now):
        if self.trial:
            self._judge(now)
        if self._restart_at is not None:
            if now >= self._restart_at:
                self.outcome = "restart"
            return
        if now < self._next_look:
            return
        self._next_look = now + _LOOK_PERIOD
        stamp = self._stamp()
        if stamp == self._mtime:
            return
        self._mtime = stamp
        self._refresh()
        running = self.software.running()
        if running != self.slot:
            self.manager.say("the boot record now runs %s (%s): restarting the processes" % (
                running, self.software.version(running)))  # fmt: skip
            self._restart_at = now + _RESTART_DELAY

    def _judge(self, now):
        m = self.manager
        if any(c.stopped for c in m.children):
            stopped = [c for c in m.children if c.stopped][0]
            return self._fail("process %s %s" % (stopped.name, stopped.stopped))
        if now - self.started > float(self.settings["deadline"]):
            return self._fail("not healthy within %gs" % float(self.settings["deadline"]))
        fresh = now - 2 * float(m.settings["heartbeat"])
        if not all(c.last_beat is not None and c.last_beat >= fresh for c in m.children):
            self.healthy_since = None
            return None
        if self.healthy_since is None:
            self.healthy_since = now
        if now - self.healthy_since < float(self.settings["healthy_after"]):
            return None
        try:
            self.proxy.self_test()
        except ComponentError as e:
            return self._fail("self-test: %s" % e)
        except InteractionError:
            return None  # the PUS process is busy or restarting: the deadline decides
        self.trial = False
        self.software.confirm()
        self._mtime = self._stamp()
        m.say("version %s (slot %s) is healthy: confirmed" % (
            self.software.version(self.slot), self.slot))  # fmt: skip
        self._refresh()
        return None

    def _fail(self, reason):
        self.trial = False
        self.software.fail_trial(reason)
        self.manager.say("version %s (slot %s) rolled back: %s" % (
            self.software.version(self.slot), self.slot, reason))  # fmt: skip
        self.outcome = "rolled back: " + reason
        return None

    def _refresh(self):
        try:
            self.proxy.refresh()
        except InteractionError:
            pass  # the PUS process raises the events when it starts
