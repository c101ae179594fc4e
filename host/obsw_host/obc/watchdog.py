"""The OBC's hardware watchdog through the Linux watchdog device interface (``/dev/watchdog``).

As the kernel's ``Documentation/watchdog/watchdog-api.rst`` describes it: opening the device
arms the watchdog; every write to it (or the ``WDIOC_KEEPALIVE`` ioctl) is a kick; if no kick
comes within the timeout (``WDIOC_SETTIMEOUT`` sets it, in seconds; the driver may round it,
``WDIOC_GETTIMEOUT`` says what it took) the board resets. Closing the device after writing the
magic character ``V`` disarms it ("magic close"); closing without it, or the process dying,
leaves it armed, so a platform manager that hangs or dies resets the OBC.

``Watchdog(path, timeout)`` works on the real device and on a stand-in (a FIFO, or
``obsw_sim.watchdog.SimulatedWatchdog`` in tests): a device that refuses the ioctls
(``ENOTTY``, ``EINVAL``) is kicked by writes alone and keeps whatever timeout it has.
"""

import errno
import fcntl
import os
import struct

# <linux/watchdog.h>: _IOR('W', 5, int), _IOWR('W', 6, int), _IOR('W', 7, int)
WDIOC_KEEPALIVE = 0x80045705
WDIOC_SETTIMEOUT = 0xC0045706
WDIOC_GETTIMEOUT = 0x80045707
MAGIC_CLOSE = b"V"
KICK = b"k"

# the watchdog's states, as the health telemetry reports them
DISABLED = 0  # no device in the mission file
WAITING = 1  # not armed yet: waits for every critical unit's first heartbeat
FED = 2  # armed and kicked
STARVED = 3  # armed, not kicked: a critical unit is unhealthy; the OBC resets at the timeout
FAILED = 4  # the device could not be opened or written
STATE_NAMES = ("disabled", "waiting", "fed", "starved", "failed")

_NO_IOCTL = (errno.ENOTTY, errno.EINVAL, errno.EOPNOTSUPP)


class WatchdogError(OSError):
    """The watchdog device cannot be used: ``path`` and what the kernel said."""

    def __init__(self, path, error):
        super().__init__(error.errno, "watchdog %s: %s" % (path, error.strerror or error))
        self.path = path


class Watchdog:
    """One open watchdog device (see the module text); ``timeout`` in seconds or None."""

    def __init__(self, path, timeout=None):
        self.path = path
        self.requested = timeout
        self.timeout = None  # what the driver took (None: it does not say)
        self.kicks = 0
        self._fd = None

    @property
    def armed(self):
        return self._fd is not None

    def open(self):
        """Arm the watchdog; raises ``WatchdogError``. Returns self."""
        try:
            self._fd = os.open(self.path, os.O_WRONLY | os.O_NONBLOCK | os.O_CLOEXEC)
        except OSError as e:
            raise WatchdogError(self.path, e) from None
        if self.requested is not None:
            self.timeout = self._ioctl(WDIOC_SETTIMEOUT, int(self.requested))
        if self.timeout is None:
            self.timeout = self._ioctl(WDIOC_GETTIMEOUT, 0)
        return self

    def _ioctl(self, request, value):
        """The ioctl's int result, or None where the device has no ioctls (a stand-in)."""
        try:
            out = fcntl.ioctl(self._fd, request, struct.pack("i", value))
        except OSError as e:
            if e.errno in _NO_IOCTL:
                return None
            raise WatchdogError(self.path, e) from None
        return struct.unpack("i", out)[0]

    def kick(self):
        """Restart the watchdog's countdown (one write); raises ``WatchdogError``."""
        try:
            os.write(self._fd, KICK)
        except OSError as e:
            raise WatchdogError(self.path, e) from None
        self.kicks += 1

    def close(self, disarm=True):
        """Close the device; with ``disarm`` after the magic ``V`` (a planned stop)."""
        if self._fd is None:
            return
        try:
            if disarm:
                os.write(self._fd, MAGIC_CLOSE)
        except OSError:
            pass  # closing anyway: an armed watchdog resets, which is the safe side
        finally:
            os.close(self._fd)
            self._fd = None
