"""Byte links for the frame processor and the ground: serial ports and pseudo-terminal pairs.

With ``queue=N`` a link never blocks its writer: what the UART cannot take now waits in a
queue of at most N frames, written as the UART drains (``flush``, and every ``write``);
when it is full the oldest frame is dropped and counted (``dropped``): a UART nobody reads
costs frames, never the frame processor's time. Without ``queue`` a write blocks until done.
"""

import collections
import os
import select
import tty


def open_pty_pair():
    """A pseudo-terminal pair in raw mode: (controller fd, device path of the other end)."""
    controller, device = os.openpty()
    tty.setraw(device)
    path = os.ttyname(device)
    os.close(device)
    return controller, path


class _Outbox:
    """The bounded queue of a link's frames not yet written (``queue=N``; see the module)."""

    def _outbox(self, queue):
        self.queue = queue
        self.dropped = 0  # frames dropped because the queue was full
        self._out = collections.deque()
        self._head = None  # the unwritten rest of the frame being written

    def pending(self):
        """Frames waiting for the UART (the one being written included)."""
        return len(self._out) + (1 if self._head is not None else 0)

    def _queue(self, data):
        if self.pending() >= self.queue:
            self.dropped += 1
            if not self._out:  # only a frame half written: finish it, drop this one
                self.flush()
                return
            self._out.popleft()  # the oldest frame not yet begun
        self._out.append(memoryview(bytes(data)))
        self.flush()

    def flush(self):
        """Write what the UART takes now, without waiting; returns frames still pending."""
        while True:
            if self._head is None:
                if not self._out:
                    return 0
                self._head = self._out.popleft()
            try:
                n = self._send(self._head)
            except BlockingIOError:
                n = 0
            except OSError:
                self._head = None  # the device is gone: the frame is lost, as on a cut line
                self.dropped += 1
                continue
            if n < len(self._head):
                self._head = self._head[n:] if n else self._head
                return self.pending()
            self._head = None


class SerialLink(_Outbox):
    """A serial port through pyserial (a real UART or the device end of a pty)."""

    def __init__(self, port, baudrate=115200, queue=None):
        import serial

        self.name = port
        self.port = serial.Serial(port, baudrate, timeout=0, write_timeout=2)
        self.enabled = True
        self._outbox(queue)

    def _send(self, view):
        # pyserial opens the port non-blocking; its own write with write_timeout=0 would
        # retry EAGAIN in a busy loop, so the queue writes to the descriptor itself
        return os.write(self.port.fileno(), view)

    def fileno(self):
        return self.port.fileno()

    def read(self):
        n = self.port.in_waiting
        return self.port.read(n) if n else b""

    def write(self, data):
        if not self.enabled:
            return
        if self.queue:
            self._queue(data)
        else:
            self.port.write(data)

    def close(self):
        self.port.close()


class FdLink(_Outbox):
    """The controller end of a pty (what the radio would be in the real system)."""

    def __init__(self, fd, name="pty", queue=None):
        self.fd = fd
        self.name = name
        self.enabled = True
        self.carrier = True  # False: out of contact, nothing crosses either way
        os.set_blocking(fd, False)
        self._outbox(queue)

    def _send(self, view):
        return os.write(self.fd, view)

    def fileno(self):
        return self.fd

    def read(self):
        try:
            data = os.read(self.fd, 65536)
        except (BlockingIOError, OSError):
            return b""
        return data if self.carrier else b""  # read all the same: the other end never waits

    def write(self, data):
        if not self.enabled or not self.carrier:
            return
        if self.queue:
            self._queue(data)
            return
        view = memoryview(data)
        while view:
            try:
                n = os.write(self.fd, view)
            except BlockingIOError:
                select.select([], [self.fd], [], 1.0)
                continue
            view = view[n:]

    def close(self):
        try:
            os.close(self.fd)
        except OSError:
            pass
