"""A CAN bus pair the MicroPython controller processes can reach: a UDP hub on localhost.

Each bus is one UDP port; a station registers by sending any datagram, and every frame
(2-byte big-endian CAN id, then up to 8 data bytes) is forwarded to all other stations.
`HubBus` is the python-can-shaped end for `obsw_host.spacecan.adapter.CanAdapter(buses=...)`.
"""

import select
import socket
import threading

from obsw_host.net import DEFAULT_HOST


class CanHub:
    """Two buses (A, B) as UDP ports; ``kill(bus)`` cuts one (fault injection)."""

    def __init__(self, host=DEFAULT_HOST):
        self.socks = []
        self.ports = []
        self.clients = [[], []]
        self.dead = [False, False]
        self.frames = [0, 0]
        for _ in (0, 1):
            s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            s.bind((host, 0))
            s.setblocking(False)
            self.socks.append(s)
            self.ports.append(s.getsockname()[1])
        self._stop = threading.Event()
        self._thread = None

    def start(self):
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()
        return self

    def _run(self):
        while not self._stop.is_set():
            readable, _, _ = select.select(self.socks, [], [], 0.05)
            for bus, s in enumerate(self.socks):
                if s not in readable:
                    continue
                while True:
                    try:
                        data, addr = s.recvfrom(64)
                    except (BlockingIOError, ConnectionRefusedError):
                        break
                    clients = self.clients[bus]
                    if addr not in clients:
                        clients.append(addr)
                        del clients[:-16]  # restarted stations leave stale addresses behind
                    if len(data) < 2 or self.dead[bus]:
                        continue
                    self.frames[bus] += 1
                    for c in clients:
                        if c != addr:
                            try:
                                s.sendto(data, c)
                            except OSError:
                                pass

    def kill(self, bus):
        self.dead[bus] = True

    def revive(self, bus):
        self.dead[bus] = False

    def close(self):
        self._stop.set()
        if self._thread is not None:
            self._thread.join(1.0)
        for s in self.socks:
            s.close()


class HubBus:
    """A python-can-like bus (send / recv / shutdown) on one hub port."""

    def __init__(self, port, host=DEFAULT_HOST):
        self.addr = (host, port)
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind((host, 0))
        self.sock.sendto(b"", self.addr)

    def send(self, msg, timeout=None):
        cid = msg.arbitration_id
        self.sock.sendto(bytes((cid >> 8, cid & 0xFF)) + bytes(msg.data), self.addr)

    def recv(self, timeout=None):
        import can

        r, _, _ = select.select([self.sock], [], [], timeout)
        if not r:
            return None
        data = self.sock.recv(64)
        if len(data) < 2:
            return None
        return can.Message(
            arbitration_id=(data[0] << 8) | data[1], data=data[2:], is_extended_id=False
        )

    def shutdown(self):
        self.sock.close()
