"""Message kinds of the interaction layer and the publication record subscribers receive.

Inside a process messages are tuples put on queues, never serialized:

    request      (kind, corr, component, member, payload, chain, origin)
    reply        (REPLY, corr, status, value)
    status       (STATUS, corr, state, value)      progress of an asynchronous operation
    publication  (PUBLISH, component, member, value)

``chain`` names the components that wait, in order, for this request (cycle detection);
``origin`` is whatever the reply goes back to (a waiting call, or a connection). Between
processes the same tuples without ``origin`` travel as CBOR arrays.
"""

from obsw.compat import const

CALL = const(1)
GET = const(2)
SET = const(3)
SUBSCRIBE = const(4)
UNSUBSCRIBE = const(5)
REPLY = const(6)
STATUS = const(7)
PUBLISH = const(8)

ACCEPTED = const(10)  # reply status: an asynchronous operation was started

# states in STATUS messages
RUNNING = const(1)
SUCCEEDED = const(2)
FAILED = const(3)

WILDCARD = "*"  # subscribe to every attribute and event of a component

KIND_NAMES = {
    CALL: "call",
    GET: "get",
    SET: "set",
    SUBSCRIBE: "subscribe",
    UNSUBSCRIBE: "unsubscribe",
    REPLY: "reply",
    STATUS: "status",
    PUBLISH: "publish",
}


class Publication:
    """One attribute update or event as a subscriber receives it."""

    def __init__(self, component, member, value):
        self.component = component
        self.member = member
        self.value = value

    @property
    def name(self):
        return self.component + "." + self.member

    def __eq__(self, other):
        return (
            isinstance(other, Publication)
            and self.component == other.component
            and self.member == other.member
            and self.value == other.value
        )

    def __repr__(self):
        return "Publication(%s.%s=%r)" % (self.component, self.member, self.value)


def split_name(target):
    """``"SolarPanel.set_angle"`` -> ``("SolarPanel", "set_angle")``."""
    i = target.rfind(".") if isinstance(target, str) else -1
    if i <= 0 or i == len(target) - 1:
        raise ValueError("expected 'Component.member', got %r" % (target,))
    return target[:i], target[i + 1 :]
