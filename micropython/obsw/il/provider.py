"""The provider side: a component's implementation behind its inbox queue.

The implementation is a plain object. Attributes are its Python attributes (a property can
validate a set by raising); operations are its methods, named as in the interface. The
method of an asynchronous operation gets a ``Job`` before its arguments and reports through
it. The provider publishes attribute updates with ``update`` and events with ``emit``.
"""

from obsw.il.errors import (
    BUSY,
    OK,
    ArgumentError,
    ReadOnlyError,
    UnknownMemberError,
    error_reply,
)
from obsw.il.interface import ATTRIBUTE, CONFIGURATION, OPERATION
from obsw.il.message import (
    ACCEPTED,
    CALL,
    FAILED,
    GET,
    REPLY,
    RUNNING,
    SET,
    STATUS,
    SUCCEEDED,
)
from obsw.il.queue import BLOCK, OVERWRITE_OLDEST, Queue


class Job:
    """The provider's handle on one running asynchronous operation."""

    def __init__(self, provider, operation, corr, origin):
        self.provider = provider
        self.operation = operation
        self.corr = corr
        self.origin = origin
        self.done = False
        self._held = []  # status sent before the call was acknowledged

    def _send(self, state, value):
        msg = (STATUS, self.corr, state, value)
        if self._held is not None:
            self._held.append(msg)
        elif self.origin is not None:
            self.origin.deliver(msg)

    def _release(self):
        held = self._held
        self._held = None
        if self.origin is not None:
            for msg in held:
                self.origin.deliver(msg)

    def update(self, value):
        """Report progress (any value) to the caller."""
        if not self.done:
            self._send(RUNNING, value)

    def succeed(self, value=None):
        """Finish with a result."""
        if not self.done:
            self.done = True
            self._send(SUCCEEDED, value)

    def fail(self, error):
        """Finish with an error: an exception, or a message string."""
        if not self.done:
            self.done = True
            if isinstance(error, str):
                error = RuntimeError(error)
            status, value = error_reply(error)
            self._send(FAILED, [status, value])


class Provider:
    """A registered implementation of an interface, with its inbox."""

    local = True

    def __init__(self, node, interface, impl, inbox=8, policy=BLOCK):
        self.node = node
        self.interface = interface
        self.name = interface.name
        self.impl = impl
        self.inbox = Queue(inbox, policy, clock=node.clock, copy=False, name=interface.name)
        self.busy = False
        self.handled = 0
        self.rejected = 0
        self._ops = {}
        for op in interface.operations:
            entry = (op, getattr(impl, op.name))
            self._ops[op.name] = entry
            self._ops[op.id] = entry

    def __repr__(self):
        return "Provider(%s, %r)" % (self.name, self.inbox)

    # -------------------------------------------------------------------------- publishing

    def update(self, name, value):
        """Set attribute ``name`` of the implementation and publish the new value."""
        m = self.interface.members.get(name)
        if m is None or m.member != ATTRIBUTE:
            raise UnknownMemberError("%s has no attribute %r" % (self.name, name), self.name)
        setattr(self.impl, name, value)
        self.node.publish(self.name, name, value)

    def emit(self, name, payload=None):
        """Publish event ``name`` with ``payload``."""
        m = self.interface.members.get(name)
        if m is None or m.member == OPERATION:
            raise UnknownMemberError("%s has no event %r" % (self.name, name), self.name)
        self.node.publish(self.name, name, payload)

    # -------------------------------------------------------------------------- serving

    def accept(self, msg):
        """Queue a request under the inbox's full policy; refuse it with BUSY otherwise."""
        q = self.inbox
        if q.send(msg):
            return True
        if q.policy == OVERWRITE_OLDEST:
            old = q.receive()
            q.dropped += 1
            self._refuse(old)
            return q.send(msg)
        if q.policy == BLOCK and not self.busy:
            self.step()  # in one thread the blocked sender is the one to make room
            if q.send(msg):
                return True
        q.dropped += 1
        self._refuse(msg)
        return False

    def _refuse(self, msg):
        self.rejected += 1
        origin = msg[6]
        if origin is not None:
            why = "%s inbox full (%d messages)" % (self.name, self.inbox.length)
            origin.deliver((REPLY, msg[1], BUSY, ["BusyError", why, self.inbox.length]))

    def step(self):
        """Handle the oldest message in the inbox; False if there was none."""
        if self.busy or not self.inbox._count:
            return False
        self.handle(self.inbox.receive())
        return True

    def run(self):
        """Handle messages until the inbox is empty; return how many."""
        n = 0
        while self.step():
            n += 1
        return n

    def handle(self, msg):
        kind, corr, _, member, payload, chain, origin = msg
        busy = self.node._busy
        mark = len(busy)
        for c in chain:
            if c not in busy:
                busy.append(c)
        busy.append(self.name)
        self.busy = True
        job = None
        try:
            if kind == CALL:
                entry = self._ops.get(member)
                if entry is None:
                    raise UnknownMemberError(
                        "%s has no operation %r" % (self.name, member), self.name
                    )
                op, fn = entry
                if len(payload) != len(op.params):
                    raise ArgumentError(
                        "%s.%s takes %d argument(s) (%s), got %d"
                        % (self.name, op.name, len(op.params), ", ".join(op.params), len(payload)),
                        self.name,
                    )
                if op.asynchronous:
                    job = Job(self, op, corr, origin)
                    fn(job, *payload)
                    status, value = ACCEPTED, None
                else:
                    status, value = OK, fn(*payload)
            elif kind == GET:
                m = self._attribute(member)
                status, value = OK, getattr(self.impl, m.name)
            elif kind == SET:
                m = self._attribute(member)
                if m.kind != CONFIGURATION:
                    raise ReadOnlyError(
                        "%s.%s is a data attribute (read-only)" % (self.name, m.name), self.name
                    )
                setattr(self.impl, m.name, payload)
                status, value = OK, None
            else:
                raise UnknownMemberError("request kind %r not served" % (kind,), self.name)
        except Exception as e:  # a provider's failure goes back to its caller, never up
            status, value = error_reply(e)
            if job is not None:
                job.done = True
                job._held = []
                job = None
        finally:
            del busy[mark:]
            self.busy = False
        self.handled += 1
        if origin is not None:
            origin.deliver((REPLY, corr, status, value))
        if job is not None:
            job._release()
        if kind == SET and status == OK:
            self.node.publish(self.name, m.name, getattr(self.impl, m.name))

    def _attribute(self, member):
        m = self.interface.member(member)
        if m is None or m.member != ATTRIBUTE:
            raise UnknownMemberError("%s has no attribute %r" % (self.name, member), self.name)
        return m
