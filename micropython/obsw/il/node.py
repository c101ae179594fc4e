"""The interaction layer of one process: providers, calls, publications and cycle detection.

A ``Node`` holds the registry of the process. ``provide`` registers an implementation under
its interface's name; ``proxy`` builds a proxy; ``call``/``get``/``set``/``subscribe`` are the
direct path by name (``"SolarPanel.set_angle"``). Inside the process requests are tuples put
on the provider's inbox and the waiting caller runs the provider until its reply is there;
nothing is serialized. A transport (host only) plugs in through ``registry.resolver``,
``wait`` and ``deliver`` to reach other processes.

Synchronous callers are tracked on a stack of waiting components; a call to a component that
is already waiting (A waits on B, B calls A) fails at once with ``CycleError`` naming the
cycle. Requests carry that chain, so the check also holds across processes.
"""

from obsw.il.calls import Calls
from obsw.il.clock import REAL_CLOCK
from obsw.il.errors import (
    OK,
    UNAVAILABLE,
    UNKNOWN_MEMBER,
    UnknownMemberError,
    cycle_error,
)
from obsw.il.interface import ATTRIBUTE, OPERATION
from obsw.il.message import (
    CALL,
    GET,
    PUBLISH,
    REPLY,
    SET,
    STATUS,
    SUBSCRIBE,
    UNSUBSCRIBE,
    WILDCARD,
    Publication,
    split_name,
)
from obsw.il.provider import Provider
from obsw.il.proxy import Proxy, Subscription
from obsw.il.queue import BLOCK, OVERWRITE_OLDEST, Queue
from obsw.il.registry import Registry


class Node(Calls):
    """One process's interaction layer (see the module text)."""

    def __init__(self, name="node", clock=None, resolve_interval=0.05):
        self.name = name
        self.clock = clock if clock is not None else REAL_CLOCK
        self.registry = Registry()
        self.resolve_interval = resolve_interval
        self.wait = self.clock.sleep  # a transport replaces this with an I/O-aware wait
        self.listeners = []  # told on_provide(provider) / on_withdraw(provider)
        self.retries = 0  # attempts repeated after a timeout or an unreachable provider
        self.late_replies = 0
        self._busy = []  # components waiting or running, outermost first
        self._waits = {}  # component -> the component it waits on (for remote requests)
        self._pending = {}  # corr -> Pending, for calls that went to another process
        self._corr = 0
        self._subs = {}  # (component, member) -> [Subscription or link]
        self._callback_subs = []
        self._remote_topics = {}  # (component, member) -> local subscriptions of a remote topic
        self._activity = None  # asyncio.Event while serve() runs

    def __repr__(self):
        return "Node(%s, %s)" % (self.name, self.registry.names())

    # -------------------------------------------------------------------------- providers

    def provide(self, interface, impl, inbox=8, policy=BLOCK):
        """Register ``impl`` as the provider of ``interface``; return the ``Provider``.

        If ``impl`` has a method ``il_bind`` it is called with the provider, which is how an
        implementation gets the handle it publishes through.
        """
        p = Provider(self, interface, impl, inbox, policy)
        self.registry.register(interface.name, p)
        bind = getattr(impl, "il_bind", None)
        if bind is not None:
            bind(p)
        for listener in self.listeners:
            listener.on_provide(p)
        return p

    def withdraw(self, provider):
        """Unregister a provider (it stops, or is about to be replaced by a restart)."""
        self.registry.unregister(provider.name, provider)
        for key in [k for k in self._subs if k[0] == provider.name]:
            self._subs[key] = [s for s in self._subs[key] if isinstance(s, Subscription)]
        for listener in self.listeners:
            listener.on_withdraw(provider)

    def providers(self):
        return [r for r in self.registry._routes.values() if getattr(r, "local", False)]

    # -------------------------------------------------------------------------- users

    def proxy(self, interface, *, timeout, retries=0, user=None):
        """A ``Proxy`` for ``interface``; every call on it uses ``timeout`` and ``retries``."""
        return Proxy(self, interface, timeout, retries, user)

    def call(self, target, args=(), *, timeout, retries=0, user=None):
        """Call operation ``"Component.operation"`` with ``args`` and wait for its value.

        An asynchronous operation gives its ``Pending`` once it has started.
        """
        comp, member = split_name(target)
        return self._request(CALL, comp, member, tuple(args), timeout, retries, user)

    def start(self, target, args=(), *, timeout, user=None, on_status=None):
        """Send a call without waiting; return its ``Pending`` (asynchronous invocation)."""
        comp, member = split_name(target)
        return self._start(comp, member, tuple(args), timeout, user, on_status)

    def get(self, target, *, timeout, retries=0, user=None):
        comp, member = split_name(target)
        return self._request(GET, comp, member, None, timeout, retries, user)

    def set(self, target, value, *, timeout, retries=0, user=None):
        comp, member = split_name(target)
        return self._request(SET, comp, member, value, timeout, retries, user)

    async def acall(self, target, args=(), *, timeout, retries=0, user=None):
        comp, member = split_name(target)
        return await self._arequest(CALL, comp, member, tuple(args), timeout, retries, user)

    async def aget(self, target, *, timeout, retries=0, user=None):
        comp, member = split_name(target)
        return await self._arequest(GET, comp, member, None, timeout, retries, user)

    async def aset(self, target, value, *, timeout, retries=0, user=None):
        comp, member = split_name(target)
        return await self._arequest(SET, comp, member, value, timeout, retries, user)

    # -------------------------------------------------------------------------- publications

    def subscribe(
        self,
        target,
        callback=None,
        queue=None,
        *,
        timeout,
        length=8,
        policy=OVERWRITE_OLDEST,
        retries=0,
    ):
        """Subscribe to ``"Component.member"`` (an attribute or event, or ``"*"``).

        Publications go to ``queue`` (default: a new one of ``length`` with ``policy``);
        ``callback(publication)`` runs from ``poll``/``serve`` if given. Waits up to
        ``timeout`` for the provider to confirm; a remote subscription is renewed whenever the
        provider comes back after a restart.
        """
        comp, member = split_name(target)
        route = self._resolve(comp, self._deadline(timeout))
        if route.local:
            _check_topic(route.interface, member)
        else:
            key = (comp, member)
            if not self._remote_topics.get(key):
                self._request(SUBSCRIBE, comp, member, None, timeout, retries, None)
            self._remote_topics[key] = self._remote_topics.get(key, 0) + 1
        if queue is None:
            queue = Queue(length, policy, clock=self.clock, copy=False, name=target)
        sub = Subscription(self, comp, member, queue, callback)
        self._subs.setdefault((comp, member), []).append(sub)
        if callback is not None:
            self._callback_subs.append(sub)
        return sub

    def watch(self, target, callback=None, *, length=8, policy=OVERWRITE_OLDEST):
        """Subscribe to ``"Component.member"`` whether or not its provider is there now.

        Nothing waits: a provider in another process, now or once it appears (or comes back
        after a restart), is subscribed by the transport as soon as its name resolves. A
        member the interface lacks is refused only when the provider is local (known now).
        """
        comp, member = split_name(target)
        route = self.registry.resolve(comp)
        if route is not None and route.local:
            _check_topic(route.interface, member)
        else:
            key = (comp, member)
            if not self._remote_topics.get(key) and route is not None:
                route.send((SUBSCRIBE, 0, comp, member, None, (), None))
            self._remote_topics[key] = self._remote_topics.get(key, 0) + 1
        queue = Queue(length, policy, clock=self.clock, copy=False, name=target)
        sub = Subscription(self, comp, member, queue, callback)
        self._subs.setdefault((comp, member), []).append(sub)
        if callback is not None:
            self._callback_subs.append(sub)
        return sub

    def _unsubscribe(self, sub):
        key = (sub.component, sub.member)
        subs = self._subs.get(key)
        if subs and sub in subs:
            subs.remove(sub)
        if sub in self._callback_subs:
            self._callback_subs.remove(sub)
        count = self._remote_topics.get(key)
        if count:
            if count > 1:
                self._remote_topics[key] = count - 1
                return
            del self._remote_topics[key]
            route = self.registry.resolve(sub.component)
            if route is not None and not route.local:
                route.send((UNSUBSCRIBE, 0, sub.component, sub.member, None, (), None))

    def subscribed_remotely(self):
        """True while this node has a subscription in another process."""
        return bool(self._remote_topics)

    def remote_components(self):
        """The components this node has subscribed to in another process."""
        return {k[0] for k in self._remote_topics}

    def remote_topics(self, component):
        """Members of ``component`` this node has subscribed to in another process."""
        return [k[1] for k in self._remote_topics if k[0] == component]

    def publish(self, component, member, value):
        """Hand a publication to every subscriber; return how many got it."""
        subs = self._subs.get((component, member))
        wild = self._subs.get((component, WILDCARD))
        if not subs and not wild:
            return 0
        pub = Publication(component, member, value)
        n = 0
        if subs:
            for s in subs:
                s.push(pub)
            n = len(subs)
        if wild:
            for s in wild:
                s.push(pub)
            n += len(wild)
        return n

    # -------------------------------------------------------------------------- scheduling

    def poll(self):
        """Run every idle provider until its inbox is empty and every subscription callback;
        return how many messages were handled."""
        n = 0
        for p in self.providers():
            if not p.busy:
                n += p.run()
        for s in self._callback_subs:
            q = s.queue
            while q._count:
                s.callback(q.receive())
                n += 1
        return n

    async def serve(self):
        """An asyncio task that handles messages as they come (``poll`` on activity)."""
        import asyncio  # only here: boards without asyncio still import this module

        self._activity = ev = asyncio.Event()
        try:
            while True:
                ev.clear()
                if not self.poll():
                    await ev.wait()
                else:
                    await asyncio.sleep(0)
        finally:
            self._activity = None

    # -------------------------------------------------------------------------- transport side

    def deliver(self, msg, origin):
        """A message from another process; replies go back through ``origin.deliver``."""
        kind = msg[0]
        if kind == REPLY or kind == STATUS:
            p = self._pending.get(msg[1])
            if p is not None:
                p.deliver(msg)
            elif msg[1]:
                self.late_replies += 1
            return
        if kind == PUBLISH:
            self.publish(msg[1], msg[2], msg[3])
            return
        corr = msg[1]
        comp = msg[2]
        route = self.registry._routes.get(comp)
        if route is None or not route.local:
            self._answer(origin, corr, UNAVAILABLE, "no provider for %s in %s" % (comp, self.name))
            return
        if kind == SUBSCRIBE or kind == UNSUBSCRIBE:
            self._remote_subscribe(route, kind, corr, msg[3], origin)
            return
        chain = msg[5]
        if route.busy:
            cycle = None
            if comp in chain:
                cycle = list(chain[chain.index(comp) :]) + [comp]
            else:
                waits_on = self._waits.get(comp)
                if waits_on is not None and waits_on in chain:
                    cycle = [comp] + list(chain[chain.index(waits_on) :]) + [comp]
            if cycle is not None:
                err = cycle_error(cycle, "%s.%s" % (comp, msg[3]))
                origin.deliver((REPLY, corr, err.status, ["CycleError", err.message, cycle]))
                return
        route.accept((kind, corr, comp, msg[3], msg[4], chain, origin))
        if not route.busy:
            route.run()

    def _answer(self, origin, corr, status, message):
        if origin is not None:
            names = {UNAVAILABLE: "UnavailableError", UNKNOWN_MEMBER: "UnknownMemberError"}
            origin.deliver((REPLY, corr, status, [names.get(status, "Error"), message, None]))

    def _remote_subscribe(self, provider, kind, corr, member, origin):
        key = (provider.name, member)
        if kind == UNSUBSCRIBE:
            subs = self._subs.get(key)
            if subs and origin in subs:
                subs.remove(origin)
            return
        try:
            _check_topic(provider.interface, member)
        except UnknownMemberError as e:
            self._answer(origin, corr, UNKNOWN_MEMBER, e.message)
            return
        subs = self._subs.setdefault(key, [])
        if origin not in subs:
            subs.append(origin)
        origin.deliver((REPLY, corr, OK, None))

    def link_lost(self, link):
        """A transport lost ``link``: fail what waits on it, drop what it subscribed."""
        self.registry.forget_route(link)
        for p in list(self._pending.values()):
            if p.route is link:
                self._pending.pop(p.corr, None)
                p._lose()
        for subs in self._subs.values():
            if link in subs:
                subs.remove(link)


def _check_topic(interface, member):
    if member == WILDCARD:
        return
    m = interface.members.get(member)
    if m is None or m.member == OPERATION:
        raise UnknownMemberError(
            "%s has no attribute or event %r to subscribe to" % (interface.name, member),
            interface.name,
        )
    return m is not None and m.member == ATTRIBUTE
