"""Radio interfaces of the ground station: what SDR and TNC software speaks.

Each is a link for ``obsw_host.frames.ground.Ground`` (``fileno``, ``read``, ``write``,
``close``; ``soft`` when ``read`` gives soft symbols instead of octets):

==================  ===========================================================================
``KissSerial``      KISS frames over a serial port (a TNC; pyserial)
``KissTcpClient``   KISS over TCP to a server (Direwolf's KISS port, a gr-satellites KISS
                    server block)
``KissTcpServer``   KISS over TCP for one client at a time (SatNOGS, a gr-satellites KISS
                    client block)
``UdpLink``         a GNU Radio flowgraph on UDP: ``octets`` (packed hard bits), ``bits`` (one
                    bit per octet, GNU Radio's unpacked bytes), ``int8`` or ``float32`` soft
                    symbols (positive means 1); uplink octets go to ``peer``
==================  ===========================================================================

Downlink KISS frames carry the channel octets of TM frames (what the OBC's ``TmEncoder``
gives; the station's decoder finds the frames in them, so one CADU per KISS frame or any other
cut works); each uplink write (a CLTU) is one KISS data frame. ``open_link(spec)`` makes one
from a command-line word: ``kiss-serial:/dev/ttyUSB0[@9600]``, ``kiss-tcp:HOST:PORT``,
``kiss-listen:HOST:PORT``, ``udp:PORT[:FORMAT][@HOST:PORT]`` (the peer for the uplink), or a
plain device path (raw octets on a serial port).
"""

import array
import socket

from obsw.frames import kiss

from obsw_host.errors import UserError

FORMATS = ("octets", "bits", "int8", "float32")


class _Kiss:
    """KISS on a byte stream: ``read`` gives the payloads of the data frames completed."""

    soft = False

    def _kiss(self, port=0):
        self.kiss_port = port
        self.decoder = kiss.KissDecoder()
        self.enabled = True
        self.written = 0

    def read(self):
        data = self._recv()
        return b"".join(self.decoder.feed(data)) if data else b""

    def write(self, data):
        if not self.enabled:
            return
        self._send(kiss.encode(data, self.kiss_port))
        self.written += 1


class KissSerial(_Kiss):
    """KISS over the serial port ``path`` at ``baudrate``."""

    def __init__(self, path, baudrate=9600, port=0):
        import serial

        self.name = path
        self.serial = serial.Serial(path, baudrate, timeout=0, write_timeout=2)
        self._kiss(port)

    def fileno(self):
        return self.serial.fileno()

    def _recv(self):
        n = self.serial.in_waiting
        return self.serial.read(n) if n else b""

    def _send(self, data):
        self.serial.write(data)

    def close(self):
        self.serial.close()


class _TcpStream:
    sock = None

    def _recv(self):
        if self.sock is None:
            return b""
        try:
            data = self.sock.recv(65536)
        except BlockingIOError:
            return b""
        except OSError:
            data = b""
        if not data:
            self._lost()
        return data

    def _send(self, data):
        if self.sock is None:
            self.dropped += 1  # nobody connected: the CLTU is lost, as on a radio off the air
            return
        try:
            self.sock.sendall(data)
        except OSError:
            self.dropped += 1
            self._lost()

    def _lost(self):
        if self.sock is not None:
            self.sock.close()
        self.sock = None


class KissTcpClient(_TcpStream, _Kiss):
    """KISS over a TCP connection to ``(host, port)``."""

    def __init__(self, host, port, port_number=0, timeout=5.0):
        self.name = "kiss-tcp:%s:%d" % (host, port)
        self.dropped = 0
        self.sock = socket.create_connection((host, port), timeout)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.sock.setblocking(False)
        self._kiss(port_number)

    def fileno(self):
        return self.sock.fileno() if self.sock is not None else -1

    def close(self):
        self._lost()


class KissTcpServer(_TcpStream, _Kiss):
    """KISS over TCP: listens on ``(host, port)`` (0: any free port, see ``address``) and
    serves one client at a time; a new client replaces the old one."""

    def __init__(self, host="127.0.0.1", port=0, port_number=0):
        self.server = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self.server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.server.bind((host, port))
        self.server.listen(1)
        self.server.setblocking(False)
        self.address = self.server.getsockname()
        self.name = "kiss-listen:%s:%d" % self.address[:2]
        self.dropped = 0
        self.clients = 0
        self._kiss(port_number)

    def fileno(self):
        return self.sock.fileno() if self.sock is not None else self.server.fileno()

    def accept(self):
        """Take a waiting client, if any (``read`` does it too); True when one is connected."""
        try:
            sock, _ = self.server.accept()
        except BlockingIOError:
            return self.sock is not None
        self._lost()
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        sock.setblocking(False)
        self.sock = sock
        self.clients += 1
        self.decoder = kiss.KissDecoder()
        return True

    def read(self):
        if self.sock is None:
            self.accept()
            return b""
        self.accept()
        return _Kiss.read(self)

    def close(self):
        self._lost()
        self.server.close()


class UdpLink:
    """A GNU Radio flowgraph on UDP: datagrams on ``(host, port)`` in ``fmt`` (see the
    module); CLTUs written go, as octets, to ``peer`` (None: nowhere, counted)."""

    def __init__(self, port=0, fmt="octets", host="127.0.0.1", peer=None):
        if fmt not in FORMATS:
            raise ValueError("UDP format %r; expected one of %s" % (fmt, ", ".join(FORMATS)))
        self.fmt = fmt
        self.soft = fmt != "octets"
        self.peer = peer
        self.enabled = True
        self.dropped = 0
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
        self.sock.bind((host, port))
        self.sock.setblocking(False)
        self.address = self.sock.getsockname()
        self.name = "udp:%d:%s" % (self.address[1], fmt)

    def fileno(self):
        return self.sock.fileno()

    def read(self):
        chunks = []
        while True:
            try:
                chunks.append(self.sock.recv(65536))
            except (BlockingIOError, ConnectionRefusedError):
                break
        data = b"".join(chunks)
        if self.fmt == "octets":
            return data
        if self.fmt == "bits":
            return [1.0 if b & 1 else -1.0 for b in data]
        if self.fmt == "int8":
            return array.array("b", data).tolist()
        return array.array("f", data[: len(data) - len(data) % 4]).tolist()

    def write(self, data):
        if not self.enabled:
            return
        if self.peer is None:
            self.dropped += 1
            return
        try:
            self.sock.sendto(data, self.peer)
        except OSError:
            self.dropped += 1

    def close(self):
        self.sock.close()


def _hostport(text, what):
    host, _, port = text.rpartition(":")
    try:
        return host or "127.0.0.1", int(port)
    except ValueError:
        raise UserError("%s %r" % (what, text), expected="HOST:PORT") from None


def open_link(spec):
    """A link from its command-line word (see the module)."""
    kind, _, rest = spec.partition(":")
    if kind == "kiss-serial":
        path, _, baud = rest.partition("@")
        return KissSerial(path, int(baud) if baud else 9600)
    if kind == "kiss-tcp":
        return KissTcpClient(*_hostport(rest, "kiss-tcp"))
    if kind == "kiss-listen":
        return KissTcpServer(*_hostport(rest, "kiss-listen"))
    if kind == "udp":
        where, _, peer = rest.partition("@")
        port, _, fmt = where.partition(":")
        try:
            return UdpLink(int(port), fmt or "octets",
                           peer=_hostport(peer, "udp peer") if peer else None)  # fmt: skip
        except ValueError as e:
            raise UserError("link %r" % spec, expected=str(e)) from None
    if spec.startswith("/"):
        from obsw_host.frames.links import SerialLink

        return SerialLink(spec)
    raise UserError(
        "link %r" % spec,
        expected="kiss-serial:DEV[@BAUD], kiss-tcp:HOST:PORT, kiss-listen:HOST:PORT, "
        "udp:PORT[:octets|bits|int8|float32][@HOST:PORT] or a device path",
    )
