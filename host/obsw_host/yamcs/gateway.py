"""The packet gateway: Yamcs' TCP packet links on one side, the OBC's UDP processes on the other.

In packet mode it stands where the frame processor stands in frame mode, with the same UDP
conventions: telecommand packets from Yamcs go to the address ``routes`` gives their APID, else
to the run's ``Ports.for_apid`` (``port_base + APID`` when ``port_base`` is given), sent from
the ``tm_port`` socket, so an application that answers the sender reaches the TM input; every
packet arriving on ``tm_port`` goes to Yamcs over TCP, on the connection of its stream
(``apids``: stream name -> APIDs, the rest on ``pus``). Yamcs connects to the gateway
(``TcpTcTmDataLink``, ``TcpTmDataLink``); every socket is bound to 127.0.0.1 unless told
otherwise (``host``; ``udp_host`` for the UDP socket alone, the one that faces OBCs on other
machines). Packets for a stream with no connection are dropped and counted, as a radio link
without a ground station would lose them.
"""

import select
import socket
import threading

from obsw.frames.processor import split_packets

from obsw_host.mission.ports import Ports


class PacketGateway:
    """TCP servers for Yamcs (one per stream) and one UDP socket for the OBC (see the module)."""

    def __init__(
        self,
        host="127.0.0.1",
        tcp_ports=None,
        apids=None,
        tm_port=None,
        port_base=None,
        routes=None,
        udp_host=None,
    ):
        self.host = host
        ports = Ports()  # the defaults of this run (obsw_host.mission.ports)
        self.default_route = (
            ports.route(host) if port_base is None else (lambda apid: (host, port_base + apid))
        )
        tm_port = ports.tm if tm_port is None else tm_port
        self.routes = dict(routes or {})
        self.apids = {a: name for name, group in (apids or {}).items() for a in group}
        self.counters = {"tc": 0, "tm": 0, "tm_dropped": 0, "tc_invalid": 0}
        self.servers = {}
        self.ports = {}
        self.clients = {}  # stream name -> connected socket
        self._buffers = {}  # socket -> bytes received not yet a whole packet
        self._stop = threading.Event()
        self._thread = None
        try:
            for name, port in (tcp_ports or {"pus": 0}).items():
                s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
                s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
                s.bind((host, port))
                s.listen(1)
                self.servers[s] = name
                self.ports[name] = s.getsockname()[1]
            self.udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            self.udp.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
            self.udp.bind((host if udp_host is None else udp_host, tm_port))
            self.udp.setblocking(False)
            self.tm_address = self.udp.getsockname()
        except OSError:
            self.close()
            raise

    def connected(self, name="pus"):
        return name in self.clients

    def _accept(self, server):
        name = self.servers[server]
        conn, _ = server.accept()
        conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        old = self.clients.pop(name, None)
        if old is not None:
            self._drop(old)
        self.clients[name] = conn
        self._buffers[conn] = b""

    def _drop(self, conn):
        self._buffers.pop(conn, None)
        for name, c in list(self.clients.items()):
            if c is conn:
                del self.clients[name]
        conn.close()

    def _from_yamcs(self, conn):
        try:
            data = conn.recv(65536)
        except OSError:
            data = b""
        if not data:
            self._drop(conn)
            return
        buf = self._buffers[conn] + data
        packets, leftover = split_packets(buf)
        self._buffers[conn] = buf[len(buf) - leftover :] if leftover else b""
        for p in packets:
            apid = ((p[0] & 7) << 8) | p[1]
            address = self.routes.get(apid) or self.default_route(apid)
            try:
                self.udp.sendto(p, address)
                self.counters["tc"] += 1
            except OSError:
                self.counters["tc_invalid"] += 1

    def _to_yamcs(self):
        while True:
            try:
                p = self.udp.recv(65542)
            except OSError:  # nothing more (or an ICMP error from a TC sent earlier)
                return
            if len(p) < 7:
                self.counters["tm_dropped"] += 1
                continue
            apid = ((p[0] & 7) << 8) | p[1]
            conn = self.clients.get(self.apids.get(apid, "pus"))
            if conn is None:
                self.counters["tm_dropped"] += 1
                continue
            try:
                conn.sendall(p)
                self.counters["tm"] += 1
            except OSError:
                self.counters["tm_dropped"] += 1
                self._drop(conn)

    def step(self, timeout=0.05):
        """Wait up to ``timeout`` for traffic and move it."""
        inputs = list(self.servers) + list(self._buffers) + [self.udp]
        readable, _, _ = select.select(inputs, [], [], timeout)
        for s in readable:
            if s in self.servers:
                self._accept(s)
            elif s is self.udp:
                self._to_yamcs()
            elif s in self._buffers:
                self._from_yamcs(s)

    def run(self):
        while not self._stop.is_set():
            self.step()

    def start(self):
        """Serve in a daemon thread."""
        self._thread = threading.Thread(target=self.run, name="packet-gateway", daemon=True)
        self._thread.start()
        return self

    def close(self):
        self._stop.set()
        if self._thread is not None:
            self._thread.join(5)
            self._thread = None
        for c in list(self._buffers):
            c.close()
        self._buffers.clear()
        self.clients.clear()
        for s in list(self.servers):
            s.close()
        self.servers.clear()
        udp = getattr(self, "udp", None)
        if udp is not None:
            udp.close()

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.close()
