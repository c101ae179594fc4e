"""The user side: proxies built from an interface, pending calls and subscriptions."""

from obsw.il.errors import (
    OK,
    UNAVAILABLE,
    CallTimeoutError,
    UnavailableError,
    error_from_reply,
)
from obsw.il.interface import ATTRIBUTE
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
from obsw.il.queue import EMPTY


class Pending:
    """A call on its way: the reply, and for an asynchronous operation its status updates.

    ``accepted`` turns True when an asynchronous operation has started, ``progress`` holds
    its last update, ``done`` turns True with the outcome; ``result(timeout)`` waits for it
    and returns the value or raises the typed error.
    """

    def __init__(self, node, component, member, on_status=None):
        self.node = node
        self.component = component
        self.member = member
        self.on_status = on_status
        self.corr = 0
        self.route = None
        self.replied = False
        self.accepted = False
        self.done = False
        self.lost = False
        self.status = None
        self.value = None
        self.progress = None
        self._event = None

    @property
    def target(self):
        return "%s.%s" % (self.component, self.member)

    def __repr__(self):
        state = "done" if self.done else ("running" if self.accepted else "sent")
        return "Pending(%s, %s)" % (self.target, state)

    def deliver(self, msg):
        kind = msg[0]
        state = None
        if kind == REPLY:
            self.replied = True
            if msg[2] == ACCEPTED:
                self.accepted = True
                state = RUNNING
            else:
                self.status = msg[2]
                self.value = msg[3]
                self.done = True
                state = SUCCEEDED if msg[2] == OK else FAILED
        elif kind == STATUS:
            self.replied = True
            state = msg[2]
            if state == RUNNING:
                self.progress = msg[3]
            elif state == SUCCEEDED:
                self.status, self.value, self.done = OK, msg[3], True
            else:
                try:
                    self.status, self.value = msg[3]
                except (TypeError, ValueError):
                    self.status, self.value = UNAVAILABLE, ["?", repr(msg[3]), None]
                self.done = True
        if self.done and self.corr:
            self.node._pending.pop(self.corr, None)
        if self._event is not None:
            self._event.set()
        if self.on_status is not None and state is not None:
            self.on_status(self, state, self.progress if state == RUNNING else self.value)

    def _lose(self):
        self.lost = True
        if not self.done:
            self.status = UNAVAILABLE
            self.value = ["UnavailableError", "link to %s went down" % self.component, None]
            self.done = True
        if self._event is not None:
            self._event.set()

    def outcome(self):
        """The value, or the typed error raised; only once ``done``."""
        if self.status == OK:
            return self.value
        raise error_from_reply(self.status, self.value, self.target)

    def result(self, timeout):
        """Wait (driving the node) up to ``timeout`` seconds for the outcome."""
        self.node._wait_done(self, timeout)
        return self.outcome()

    async def wait(self, timeout):
        """``result`` for asyncio tasks."""
        import asyncio  # only here: boards without asyncio still import this module

        if not self.done:
            if self._event is None:
                self._event = asyncio.Event()
            try:
                while not self.done:
                    self._event.clear()
                    await asyncio.wait_for(self._event.wait(), timeout)
            except asyncio.TimeoutError:
                raise CallTimeoutError(
                    "no outcome of %s within %ss" % (self.target, timeout)
                ) from None
        return self.outcome()


class Subscription:
    """Publications of one attribute or event, queued for the subscriber.

    Pull them with ``receive`` / ``areceive``, or give a callback that ``Node.poll`` runs.
    The queue's full policy applies (by default the oldest publication is overwritten) and
    its ``dropped`` counter says how many were lost.
    """

    def __init__(self, node, component, member, queue, callback):
        self.node = node
        self.component = component
        self.member = member
        self.queue = queue
        self.callback = callback
        self.active = True

    def __repr__(self):
        return "Subscription(%s.%s, %r)" % (self.component, self.member, self.queue)

    def push(self, pub):
        self.queue.put(pub)
        if self.callback is not None:
            ev = self.node._activity
            if ev is not None:
                ev.set()

    @property
    def dropped(self):
        return self.queue.dropped

    def receive(self, timeout=0):
        """The next ``Publication``, or ``EMPTY`` if none came within ``timeout``."""
        q = self.queue
        if q._count or timeout == 0:
            return q.receive()
        node = self.node
        clock = node.clock
        deadline = None if timeout is None else clock.now() + timeout
        while not q._count:
            if deadline is None:
                node.wait(1.0)
                continue
            left = deadline - clock.now()
            if left <= 0:
                return EMPTY
            node.wait(left)
        return q.receive()

    async def areceive(self, timeout=None):
        return await self.queue.areceive(timeout)

    def cancel(self):
        if self.active:
            self.active = False
            self.node._unsubscribe(self)


class Proxy:
    """A component used like a local object: operations are methods, attributes are read
    with ``get`` (or as Python attributes) and written with ``set``.

    Every call uses the proxy's ``timeout`` and ``retries``. Asynchronous operations return
    a ``Pending`` at once; synchronous ones return the value or raise the typed error.
    """

    def __init__(self, node, interface, timeout, retries=0, user=None):
        if timeout is not None and timeout < 0:
            raise ValueError("timeout must be >= 0 seconds or None, got %r" % (timeout,))
        self._node = node
        self._interface = interface
        self._name = interface.name
        self._timeout = timeout
        self._retries = retries
        self._user = user
        for op in interface.operations:
            setattr(self, op.name, self._operation(op))

    def __repr__(self):
        return "Proxy(%s)" % self._name

    def _operation(self, op):
        node = self._node
        comp = self._name
        name = op.name
        params = op.params

        def _args(args, kwargs):
            if kwargs:
                args = list(args)
                for p in params[len(args) :]:
                    if p in kwargs:
                        args.append(kwargs.pop(p))
                if kwargs:
                    raise TypeError("%s.%s got unexpected %s" % (comp, name, sorted(kwargs)))
            return tuple(args)

        if op.asynchronous:

            def start(*args, **kwargs):
                on_status = kwargs.pop("on_status", None)
                return node._start(
                    comp, name, _args(args, kwargs), self._timeout, self._user, on_status
                )

            return start

        def call(*args, **kwargs):
            return node._request(
                CALL, comp, name, _args(args, kwargs), self._timeout, self._retries, self._user
            )

        return call

    def get(self, name):
        """Read attribute ``name``."""
        return self._node._request(
            GET, self._name, name, None, self._timeout, self._retries, self._user
        )

    def set(self, name, value):
        """Write configuration attribute ``name``."""
        return self._node._request(
            SET, self._name, name, value, self._timeout, self._retries, self._user
        )

    def subscribe(self, name, callback=None, queue=None, **options):
        """Subscribe to attribute or event ``name`` (``"*"`` for all); see Node.subscribe."""
        return self._node.subscribe(
            self._name + "." + name, callback, queue, timeout=self._timeout, **options
        )

    def __getattr__(self, name):
        m = self._interface.members.get(name)
        if m is not None and m.member == ATTRIBUTE:
            return self.get(name)
        raise AttributeError("%s has no attribute or operation %r" % (self._name, name))

    async def aget(self, name):
        return await self._node._arequest(
            GET, self._name, name, None, self._timeout, self._retries
        )

    async def aset(self, name, value):
        return await self._node._arequest(
            SET, self._name, name, value, self._timeout, self._retries
        )

    async def acall(self, name, *args):
        return await self._node._arequest(
            CALL, self._name, name, args, self._timeout, self._retries
        )


def unavailable(component, why):
    return UnavailableError("no provider for %s reachable: %s" % (component, why), component)
