"""A stand-in for ``/dev/watchdog`` in tests and on a development machine: a FIFO whose reader
behaves as the kernel's watchdog does.

``SimulatedWatchdog(path, timeout).start()`` makes the FIFO and reads it in a thread: the
first writer arms it, each write (one octet) is a kick, ``V`` followed by the writer's close
disarms it, a close without ``V`` leaves it armed. When it is armed and no kick came for
``timeout`` seconds it "resets the board": ``resets`` counts it, ``on_reset()`` is called, and
it waits disarmed for the next writer (a rebooted OBC). Its clock is passed in for tests.
"""

import os
import select
import threading
import time


class SimulatedWatchdog:
    """A FIFO that records kicks and resets when starved (see the module text)."""

    def __init__(self, path, timeout, *, clock=time.monotonic, on_reset=None):
        self.path = path
        self.timeout = float(timeout)
        self.clock = clock
        self.on_reset = on_reset
        self.kicks = []  # times of kicks
        self.resets = []  # times of resets
        self.armed = False
        self.disarms = 0
        self.closes = 0  # writers' closes seen
        self.rounds = 0  # times the reader thread looked at the FIFO (tests wait on it)
        self._last = None
        self._magic = False
        self._fd = None
        self._stop = threading.Event()
        self._thread = None

    def start(self):
        if not os.path.exists(self.path):
            os.mkfifo(self.path)
        self._open()
        self._thread = threading.Thread(target=self._run, name="watchdog-sim", daemon=True)
        self._thread.start()
        return self

    def _open(self):
        self._fd = os.open(self.path, os.O_RDONLY | os.O_NONBLOCK)

    def _run(self):
        while not self._stop.is_set():
            ready, _, _ = select.select([self._fd], [], [], 0.01)
            if ready:
                self._read()
            self.check()
            self.rounds += 1

    def _read(self):
        try:
            data = os.read(self._fd, 4096)
        except BlockingIOError:
            return
        now = self.clock()
        if not data:  # the writer closed the device
            self.closes += 1
            if self.armed and self._magic:
                self.armed = False
                self.disarms += 1
            os.close(self._fd)
            self._open()  # wait for the next writer
            return
        if not self.armed:
            self.armed = True
        self._magic = data.endswith(b"V")
        self.kicks.extend([now] * len(data))  # one octet per write: writes read together
        self._last = now

    def check(self):
        """Reset if armed and starved; True if it did now."""
        if not self.armed or self._last is None:
            return False
        now = self.clock()
        if now - self._last <= self.timeout:
            return False
        self.armed = False
        self.resets.append(now)
        if self.on_reset is not None:
            self.on_reset()
        return True

    def stop(self):
        self._stop.set()
        if self._thread is not None:
            self._thread.join(2.0)
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None
        if os.path.exists(self.path):
            os.remove(self.path)
