"""Two nodes of one process joined as if they ran in two processes (no sockets).

A ``LoopbackLink`` pair does what a socket transport does, synchronously and in memory: the
requests of one node reach the other's ``deliver``, replies, status and publications come
back. With ``codec=True`` every message goes through CBOR on the way, as on a socket. Tests
use it to drive cross-process behaviour (cycle detection over the wire, a provider that goes
away and comes back) on a simulated clock.
"""

from obsw.il.message import PUBLISH, SUBSCRIBE


class LoopbackLink:
    """One end of a connection, held by ``node``; ``peer`` is the other end."""

    local = False

    def __init__(self, node, codec=False):
        self.node = node
        self.peer = None
        self.alive = True
        self.codec = codec
        self.sent = 0

    def _carry(self, msg):
        if self.codec:
            from obsw.cbor import dumps, loads

            return loads(dumps(msg))
        return list(msg)

    def send(self, msg):
        """A request from ``node`` to the peer's node; False if the connection is down."""
        if not self.alive:
            return False
        self.sent += 1
        self.peer.node.deliver(self._carry(msg[:6]), self.peer)
        return True

    def deliver(self, msg):
        """A reply or status from ``node`` back to the peer's node."""
        if self.alive:
            self.sent += 1
            self.peer.node.deliver(self._carry(msg), self.peer)

    def push(self, pub):
        """A publication from ``node`` to a subscriber on the peer's node."""
        if self.alive:
            self.sent += 1
            self.peer.node.deliver(
                self._carry((PUBLISH, pub.component, pub.member, pub.value)), self.peer
            )

    def cut(self):
        """Break the connection; both nodes are told, as when a process dies."""
        if self.alive:
            self.alive = False
            self.peer.alive = False
            self.node.link_lost(self)
            self.peer.node.link_lost(self.peer)


def connect(a, b, codec=False):
    """Join nodes ``a`` and ``b``; return (a's end, b's end)."""
    end_a = LoopbackLink(a, codec)
    end_b = LoopbackLink(b, codec)
    end_a.peer = end_b
    end_b.peer = end_a
    return end_a, end_b


def resolver_for(node, peers, codec=False):
    """A ``Registry.resolver`` for ``node`` that looks names up in the nodes ``peers()``
    returns and joins to the one that provides it (as a transport's name lookup would)."""

    def resolve(name):
        for peer in peers():
            if peer is not node and name in peer.registry and peer.registry._routes[name].local:
                end, _ = connect(node, peer, codec)
                for member in node.remote_topics(name):
                    end.send((SUBSCRIBE, 0, name, member, None, (), None))
                return end
        return None

    return resolve
