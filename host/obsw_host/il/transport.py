"""Cross-process transport: a core ``Node`` reaching other processes over Unix sockets.

Each process listens on its own socket, named after its node and pid, and writes one entry
per provided component in the name ``Directory``. A user resolves a component name there on
demand and connects; one connection per peer process carries requests, replies, status
updates and publications in both directions as length-prefixed CBOR frames. When a provider
dies, the connection breaks: calls waiting on it fail over to a fresh lookup (within their
timeout and retries) and subscriptions are renewed as soon as the name resolves again, so a
restarted provider (new pid, new socket) is found again without any static port table.

The transport is single-threaded and plugs into the node's ``wait``: a caller blocked on a
remote reply keeps serving requests for its idle providers meanwhile.

    node = Node("panel")
    transport = SocketTransport(node)           # $OBSW_IL_DIR or a per-user temp directory
    node.provide(SOLAR_PANEL, SolarPanel())
    transport.serve()                           # until stop() or a signal
"""

import collections
import errno
import hashlib
import os
import select
import socket
import struct

from obsw.il.message import PUBLISH, SUBSCRIBE

from obsw_host.il.directory import Directory
from obsw_host.il.wire import CborDecodeError, FrameError, FrameReader, frame

_SUN_PATH_MAX = 100
_SLICE = 0.01  # a lone connection is waited on by a blocking recv of at most this long
# received into one buffer per connection, then copied at their size: a fresh buffer of the
# largest size per receive, shrunk to what came, left the process's heap fragmented (its
# resident memory grew for hours under traffic)
_RECV = 65536
_POLLIN = select.POLLIN | select.POLLPRI | select.POLLHUP | select.POLLERR


class Connection:
    """A link to one peer process (either direction); the node sees it as a remote route."""

    local = False

    def __init__(self, transport, sock, address=None):
        self.transport = transport
        self.sock = sock
        self.address = address  # the peer's listening address, for connections we opened
        self.alive = True
        self.reason = None
        self.sent = 0
        self.received = 0
        self._reader = FrameReader()
        self._inbound = collections.deque()
        self._fd = sock.fileno()
        self._buf = bytearray(_RECV)
        self._view = memoryview(self._buf)

    def __repr__(self):
        return "Connection(%s, %s)" % (self.address or "incoming", "up" if self.alive else "down")

    def fileno(self):
        return self._fd

    # -------------------------------------------------------------------------- out

    def _write(self, data):
        if not self.alive:
            return False
        try:
            self.sock.sendall(data)
        except OSError as e:
            self.close("send failed: %s" % e)
            return False
        self.sent += 1
        return True

    def send(self, msg):
        """A request from our node (``origin`` stripped)."""
        return self._write(frame(list(msg[:6])))

    def deliver(self, msg):
        """A reply or status update back to the peer."""
        self._write(frame(list(msg)))

    def push(self, pub):
        """A publication to a subscriber in the peer; encoded once for every connection."""
        cache = self.transport._pub_cache
        if cache[0] is pub:
            data = cache[1]
        else:
            data = frame([PUBLISH, pub.component, pub.member, pub.value])
            self.transport._pub_cache = (pub, data)
        self._write(data)

    # -------------------------------------------------------------------------- in

    def on_readable(self):
        """Read and handle what came; False if nothing came (the receive timed out)."""
        try:
            n = self.sock.recv_into(self._buf)
        except (BlockingIOError, InterruptedError):
            return False
        except OSError as e:
            self.close("receive failed: %s" % e)
            return True
        if not n:
            self.close("peer closed")
            return True
        data = bytes(self._view[:n])
        try:
            msgs = self._reader.feed(data)
        except (CborDecodeError, FrameError) as e:
            self.transport.bad_frames += 1
            self.close("bad frame: %s" % e)
            return True
        inbound = self._inbound
        inbound.extend(msgs)
        node = self.transport.node
        # a handler may wait for another reply and read this connection again (nested):
        # one queue per connection keeps the messages in the order they came
        while inbound and self.alive:
            msg = inbound.popleft()
            self.received += 1
            if type(msg) is not list or len(msg) < 4:
                self.transport.bad_frames += 1
                continue
            node.deliver(msg, self)
        return True

    def close(self, reason="closed"):
        if not self.alive:
            return
        self.alive = False
        self.reason = reason
        self.transport._forget(self)
        try:
            self.sock.close()
        except OSError:
            pass
        self.transport.node.link_lost(self)


class SocketTransport:
    """Joins ``node`` to the processes that share ``directory`` (see the module text)."""

    def __init__(self, node, directory=None, *, listen=True, send_timeout=5.0, renew=0.1):
        self.node = node
        self.directory = directory if isinstance(directory, Directory) else Directory(directory)
        self.send_timeout = send_timeout
        self.renew_interval = renew
        self.bad_frames = 0
        self.address = None
        self._server = None
        self._poll = select.poll()
        self._fds = {}
        self._by_address = {}
        self._pub_cache = (None, None)
        self._stop = False
        self._next_renew = 0.0
        self._closed = False
        self._hot = None  # the connection a provider last heard from (see wait)
        node.registry.resolver = self._resolve
        node.wait = self.wait
        node.listeners.append(self)
        if listen:
            self._listen()
            for provider in node.providers():
                self.on_provide(provider)

    def __repr__(self):
        return "SocketTransport(%s, %s, %d connections)" % (
            self.node.name,
            self.address,
            len(self._fds) - (1 if self._server else 0),
        )

    # -------------------------------------------------------------------------- naming

    def _listen(self):
        self.directory.sweep()
        path = self.directory.socket_path(self.node.name)
        if len(path.encode()) > _SUN_PATH_MAX:  # too long for sun_path: Linux abstract name
            digest = hashlib.sha1(self.directory.path.encode()).hexdigest()[:12]
            path = "\0obsw-il-%s-%s-%d" % (digest, self.node.name, os.getpid())
        elif os.path.exists(path):
            os.remove(path)
        s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        s.bind(path)
        s.listen(64)
        s.setblocking(False)
        self._server = s
        self.address = path
        self._fds[s.fileno()] = s
        self._poll.register(s.fileno(), _POLLIN)

    def on_provide(self, provider):
        if self.address is not None:
            self.directory.register(provider.name, self.address, self.node.name)

    def on_withdraw(self, provider):
        if self.address is not None:
            self.directory.unregister(provider.name, self.address)

    def _resolve(self, name):
        address = self.directory.lookup(name)
        if address is None or address == self.address:
            return None
        conn = self._by_address.get(address)
        if conn is None or not conn.alive:
            conn = self._connect(address)
            if conn is None:
                return None
        for member in self.node.remote_topics(name):
            conn.send((SUBSCRIBE, 0, name, member, None, ()))
        return conn

    def _connect(self, address):
        s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            s.connect(address)
        except OSError as e:
            s.close()
            if e.errno not in (errno.ECONNREFUSED, errno.ENOENT, errno.EAGAIN, None):
                raise
            return None
        conn = Connection(self, self._tune(s), address)
        self._add(conn)
        self._by_address[address] = conn
        return conn

    def _tune(self, s):
        """Blocking socket with a kernel send timeout: Python's own socket timeout would add
        a poll() before every send and receive; a peer that stops reading for
        ``send_timeout`` seconds gets its connection closed instead of hanging us."""
        s.setblocking(True)
        sec = int(self.send_timeout)
        usec = int((self.send_timeout - sec) * 1e6)
        s.setsockopt(socket.SOL_SOCKET, socket.SO_SNDTIMEO, struct.pack("ll", sec, usec))
        s.setsockopt(
            socket.SOL_SOCKET, socket.SO_RCVTIMEO, struct.pack("ll", 0, int(_SLICE * 1e6))
        )
        return s

    def fds(self):
        """The file descriptors the transport waits on (they change as peers come and go)."""
        return set(self._fds)

    def add_reader(self, reader):
        """Wait on ``reader`` too (``fileno()``, ``on_readable()``): one wait serves both."""
        self._add(reader)

    def remove_reader(self, reader):
        """Stop waiting on a reader ``add_reader`` gave."""
        self._forget(reader)

    def _add(self, conn):
        self._fds[conn.fileno()] = conn
        self._poll.register(conn.fileno(), _POLLIN)

    def _forget(self, conn):
        fd = conn.fileno()
        if self._fds.get(fd) is conn:
            del self._fds[fd]
            try:
                self._poll.unregister(fd)
            except (KeyError, ValueError):
                pass
        address = getattr(conn, "address", None)  # a reader of add_reader has none
        if address is not None and self._by_address.get(address) is conn:
            del self._by_address[address]

    def connections(self):
        return [c for c in self._fds.values() if isinstance(c, Connection)]

    # -------------------------------------------------------------------------- running

    def wait(self, timeout):
        """Block up to ``timeout`` seconds for I/O and handle what came; the node's wait."""
        if self._server is None and len(self._fds) == 1 and (timeout is None or timeout >= _SLICE):
            # a user with one connection: one blocking recv (bounded by SO_RCVTIMEO) instead
            # of poll() then recv(), one system call less per reply
            for conn in list(self._fds.values()):
                conn.on_readable()
            if self.node.subscribed_remotely():
                self._renew()
            return
        hot = self._hot
        if hot is not None:
            # a provider with one busy peer: wait on that connection alone with one blocking
            # recv (bounded by SO_RCVTIMEO), not poll() then recv(); once it stays quiet for
            # a slice, back to poll() over every socket (new peers are accepted then)
            self._hot = None
            if (
                hot.alive
                and len(self._fds) == 2
                and (timeout is None or timeout >= _SLICE)
                and hot.on_readable()
            ):
                if hot.alive:
                    self._hot = hot
                return
            if timeout is not None:
                timeout = max(0.0, timeout - _SLICE)
        if timeout is None:
            ms = -1
        else:
            ms = int(timeout * 1000 + 0.999) if timeout > 0 else 0
        if self.node.subscribed_remotely():
            self._renew()
            if ms < 0 or ms > self.renew_interval * 1000:
                ms = int(self.renew_interval * 1000)
        try:
            events = self._poll.poll(ms)
        except InterruptedError:  # pragma: no cover - PEP 475 retries, kept for signals
            return
        for fd, _ in events:
            obj = self._fds.get(fd)
            if obj is None:
                continue
            if obj is self._server:
                self._accept()
            elif obj.on_readable() and obj.alive and self._server is not None:
                self._hot = obj

    def _accept(self):
        while True:
            try:
                s, _ = self._server.accept()
            except (BlockingIOError, InterruptedError):
                return
            except OSError:  # pragma: no cover - out of descriptors and the like
                return
            self._add(Connection(self, self._tune(s)))

    def _renew(self):
        """Resolve components we subscribed to whose provider is not reachable right now."""
        now = self.node.clock.now()
        if now < self._next_renew:
            return
        self._next_renew = now + self.renew_interval
        registry = self.node.registry
        for comp in self.node.remote_components():
            if comp not in registry:
                registry.resolve(comp)

    def serve(self, until=None, timeout=None):
        """Serve requests (and run subscription callbacks) until ``stop()``, ``until()`` is
        true, or ``timeout`` seconds have passed."""
        clock = self.node.clock
        deadline = None if timeout is None else clock.now() + timeout
        self._stop = False
        while not self._stop and not self._closed:
            if until is not None and until():
                return True
            left = 0.2
            if deadline is not None:
                left = min(left, deadline - clock.now())
                if left <= 0:
                    return False
            self.wait(left)
            self.node.poll()
        return True

    def stop(self):
        self._stop = True

    def close(self):
        """Withdraw our names, close every connection and the listening socket."""
        if self._closed:
            return
        self._closed = True
        for provider in self.node.providers():
            self.on_withdraw(provider)
        for conn in self.connections():
            conn.close("transport closed")
        if self._server is not None:
            self._poll.unregister(self._server.fileno())
            self._server.close()
            if not self.address.startswith("\0"):
                try:
                    os.remove(self.address)
                except FileNotFoundError:
                    pass
        if self in self.node.listeners:
            self.node.listeners.remove(self)
        self.node.wait = self.node.clock.sleep
        self.node.registry.resolver = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
