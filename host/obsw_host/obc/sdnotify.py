"""systemd's service notification protocol (``sd_notify(3)``), without libsystemd.

A service of ``Type=notify`` tells systemd it is ready (``READY=1``), what it is doing
(``STATUS=...``) and that it is alive (``WATCHDOG=1``, at least once per ``WatchdogSec=``)
by sending one datagram of newline-separated ``KEY=VALUE`` lines to the unix socket named by
``$NOTIFY_SOCKET`` (a leading ``@`` names an abstract socket). systemd passes the watchdog
interval as ``$WATCHDOG_USEC`` (microseconds), meant for the process ``$WATCHDOG_PID`` if set.
Outside systemd there is no ``$NOTIFY_SOCKET`` and every call does nothing.
"""

import os
import socket


class Notifier:
    """Notifications to the socket ``address`` (None: not under systemd)."""

    def __init__(self, address=None, watchdog_usec=None):
        self.address = address
        self.watchdog = watchdog_usec / 1e6 if watchdog_usec else None  # seconds, or None
        self.sent = 0
        self.failed = 0
        self._sock = None

    @classmethod
    def from_environ(cls, environ=None):
        """The notifier systemd's environment describes (``NOTIFY_SOCKET``, ``WATCHDOG_USEC``
        and ``WATCHDOG_PID``)."""
        env = os.environ if environ is None else environ
        address = env.get("NOTIFY_SOCKET") or None
        usec = None
        pid = env.get("WATCHDOG_PID")
        if env.get("WATCHDOG_USEC") and (not pid or pid == str(os.getpid())):
            try:
                usec = int(env["WATCHDOG_USEC"])
            except ValueError:
                usec = None
        return cls(address, usec)

    @property
    def enabled(self):
        return self.address is not None

    def notify(self, **fields):
        """Send ``KEY=value`` lines (``ready=1`` becomes ``READY=1``); False if not sent."""
        if self.address is None:
            return False
        text = "\n".join("%s=%s" % (k.upper(), v) for k, v in fields.items())
        target = self.address
        if target.startswith("@"):
            target = "\0" + target[1:]
        try:
            if self._sock is None:
                self._sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
                self._sock.setblocking(False)
            self._sock.sendto(text.encode(), target)
        except OSError:  # systemd gone or restarting: its watchdog decides, not us
            self.failed += 1
            return False
        self.sent += 1
        return True

    def ready(self, status=None):
        if status is None:
            return self.notify(ready=1)
        return self.notify(ready=1, status=status)

    def status(self, text):
        return self.notify(status=text)

    def alive(self):
        return self.notify(watchdog=1)

    def stopping(self):
        return self.notify(stopping=1)

    def close(self):
        if self._sock is not None:
            self._sock.close()
            self._sock = None
