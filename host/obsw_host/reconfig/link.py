"""The OBC's side of the UART link to the reconfiguration module (`obsw.reconfig.obclink`).

An `ObcLink` talks to one or both controllers (one file descriptor each: a serial port or a
pseudo-terminal): heartbeats to all, and requests whose first good answer wins. The context
is kept in both controllers' safeguard memories; at start the newest copy is taken.
"""

import os
import select
import time

from obsw.reconfig import obclink as L

from obsw_host.obc.context import ObcContext


class ObcLink:
    """Frames to and from the controllers on ``fds`` (non-blocking reads)."""

    def __init__(self, fds):
        self.fds = list(fds)
        self.decoders = [L.Decoder() for _ in self.fds]
        self.seq = 0
        self.counters = {"write_errors": 0}

    def _send(self, frame):
        for fd in self.fds:
            try:
                os.write(fd, frame)
            except OSError:  # a controller in reset: the other one carries the link
                self.counters["write_errors"] += 1

    def heartbeat(self):
        self._send(L.heartbeat(self.seq))
        self.seq = (self.seq + 1) & 0xFFFF

    def _ask(self, frame, want, timeout):
        """The answers of type ``want``, one list per controller, within ``timeout`` s."""
        for fd in self.fds:
            _drain(fd)
        self._send(frame)
        got = [None] * len(self.fds)
        end = time.monotonic() + timeout
        while time.monotonic() < end and None in got:
            ready, _, _ = select.select(self.fds, [], [], max(0.0, end - time.monotonic()))
            for fd in ready:
                i = self.fds.index(fd)
                try:
                    data = os.read(fd, 4096)
                except OSError:
                    continue
                for t, payload in self.decoders[i].feed(data):
                    if t == want and got[i] is None:
                        got[i] = payload
        return got

    def read_time(self, timeout=1.0):
        """(day, ms) of the DS3231 through the first controller that has it, or None."""
        for payload in self._ask(L.encode(L.T_TIME_READ), L.T_TIME, timeout):
            if payload is not None:
                status, day, ms = L.parse_time(payload)
                if status == L.OK:
                    return day, ms
        return None

    def read_context(self, timeout=1.0):
        """The newest ObcContext kept by the controllers, or None."""
        best = None
        for payload in self._ask(L.encode(L.T_CONTEXT_READ), L.T_CONTEXT, timeout):
            if payload is None or payload[:1] != b"\x00":
                continue
            try:
                ctx = ObcContext.unpack(payload[1:])
            except ValueError:
                continue
            if best is None or ctx.saves > best.saves:
                best = ctx
        return best

    def write_context(self, ctx, timeout=1.0):
        """How many controllers acknowledged keeping ``ctx``."""
        got = self._ask(L.encode(L.T_CONTEXT_WRITE, ctx.pack()), L.T_ACK, timeout)
        return sum(1 for p in got if p is not None and p == bytes((L.T_CONTEXT_WRITE, L.OK)))


def _drain(fd):
    while True:
        r, _, _ = select.select([fd], [], [], 0)
        if not r:
            return
        try:
            if not os.read(fd, 4096):
                return
        except OSError:
            return
