"""The OBC's supervision chain above the platform manager: the hardware watchdog and systemd.

The platform manager watches the OBC's processes (``obsw_host.obc.platform``); this watches the
platform manager and the whole OBC:

- the **hardware watchdog** (``obsw_host.obc.watchdog``, the mission file's
  ``platform.watchdog`` device): armed once every critical process has answered its first
  heartbeat, then kicked every ``heartbeat`` seconds *only while every critical process is
  healthy* (answered a heartbeat within ``deadline``). A process being restarted starves it;
  if the restarts do not bring the OBC back within ``watchdog_timeout`` seconds, or the
  platform manager itself hangs or dies, the board resets. A process the manager stopped for
  good (a configuration mistake, see ``platform``) no longer counts: a reset cannot fix it.
  A planned stop disarms the watchdog (magic close).
- **systemd** (``obsw_host.obc.sdnotify``): ``READY=1`` when every process is up, ``STATUS=``
  when the OBC's state changes, and ``WATCHDOG=1`` at half of ``WatchdogSec=`` from the
  manager's own loop, so systemd restarts a platform manager that hangs.
"""

from obsw_host.obc import watchdog as wd
from obsw_host.obc.sdnotify import Notifier


class Supervision:
    """The watchdog and systemd side of a ``PlatformManager`` (see the module text)."""

    def __init__(self, manager, notifier=None):
        self.manager = manager
        settings = manager.settings
        critical = settings.get("critical")
        self.critical = [c for c in manager.children if critical is None or c.name in critical]
        device = settings.get("watchdog")
        self.watchdog = wd.Watchdog(device, settings.get("watchdog_timeout")) if device else None
        self.state = wd.WAITING if self.watchdog is not None else wd.DISABLED
        self.error = None
        self.notifier = notifier if notifier is not None else Notifier.from_environ()
        self._next_kick = 0.0
        self._next_alive = 0.0
        self._ready = False
        self._status = None

    # -------------------------------------------------------------------------- health

    def healthy(self, child, now):
        """Answered a heartbeat within the deadline, or stopped for good (not counted)."""
        if child.stopped:
            return True
        deadline = float(self.manager.settings["deadline"])
        return child.last_beat is not None and now - child.last_beat <= deadline

    def unhealthy(self, now):
        return [c.name for c in self.critical if not self.healthy(c, now)]

    # -------------------------------------------------------------------------- each round

    def step(self, now):
        """One round of the platform manager's loop (after it checked its processes)."""
        sick = self.unhealthy(now)
        if self.watchdog is not None and self.state != wd.FAILED:
            self._watchdog(now, sick)
        if self.notifier.enabled:
            self._systemd(now, sick)

    def _watchdog(self, now, sick):
        if sick:
            if self.watchdog.armed:
                self.state = wd.STARVED
            return
        try:
            if not self.watchdog.armed:
                self.watchdog.open()
                self.manager.say("watchdog %s armed (timeout %s s)" % (
                    self.watchdog.path, self.watchdog.timeout))  # fmt: skip
            if now >= self._next_kick:
                self.watchdog.kick()
                self._next_kick = now + float(self.manager.settings["heartbeat"])
            self.state = wd.FED
        except OSError as e:
            self.state = wd.FAILED
            self.error = str(e)
            self.manager.say("%s: the OBC runs without its hardware watchdog" % e)

    def _systemd(self, now, sick):
        n = self.notifier
        up = sum(1 for c in self.manager.children if c.last_beat is not None and not c.stopped)
        status = "%d of %d processes up" % (up, len(self.manager.children))
        if sick:
            status += "; waiting for " + ", ".join(sick)
        if not self._ready and not sick:
            self._ready = True
            n.ready(status)
            self._status = status
        elif status != self._status:
            n.status(status)
            self._status = status
        if n.watchdog is not None and now >= self._next_alive:
            n.alive()
            self._next_alive = now + n.watchdog / 2

    def stop(self):
        """A planned stop: tell systemd, disarm the watchdog."""
        self.notifier.stopping()
        self.notifier.close()
        if self.watchdog is not None:
            self.watchdog.close(disarm=True)
            if self.state != wd.FAILED:
                self.state = wd.WAITING

    # -------------------------------------------------------------------------- telemetry

    def report(self):
        """What the OBC's health telemetry shows of supervision."""
        return {
            "restarts": sum(c.restarts for c in self.manager.children),
            "watchdog": self.state,
            "kicks": self.watchdog.kicks if self.watchdog is not None else 0,
        }
