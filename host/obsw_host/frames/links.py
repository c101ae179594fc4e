"""Byte links for the frame processor and the ground: serial ports and pseudo-terminal pairs."""

import os
import tty


def open_pty_pair():
    """A pseudo-terminal pair in raw mode: (controller fd, device path of the other end)."""
    controller, device = os.openpty()
    tty.setraw(device)
    path = os.ttyname(device)
    os.close(device)
    return controller, path


class SerialLink:
    """A serial port through pyserial (a real UART or the device end of a pty)."""

    def __init__(self, port, baudrate=115200):
        import serial

        self.name = port
        self.port = serial.Serial(port, baudrate, timeout=0, write_timeout=2)
        self.enabled = True

    def fileno(self):
        return self.port.fileno()

    def read(self):
        n = self.port.in_waiting
        return self.port.read(n) if n else b""

    def write(self, data):
        if self.enabled:
            self.port.write(data)

    def close(self):
        self.port.close()


class FdLink:
    """The controller end of a pty (what the radio would be in the real system)."""

    def __init__(self, fd, name="pty"):
        self.fd = fd
        self.name = name
        self.enabled = True
        os.set_blocking(fd, False)

    def fileno(self):
        return self.fd

    def read(self):
        try:
            return os.read(self.fd, 65536)
        except (BlockingIOError, OSError):
            return b""

    def write(self, data):
        if not self.enabled:
            return
        view = memoryview(data)
        while view:
            try:
                n = os.write(self.fd, view)
            except BlockingIOError:
                import select

                select.select([], [self.fd], [], 1.0)
                continue
            view = view[n:]

    def close(self):
        try:
            os.close(self.fd)
        except OSError:
            pass
