"""The parameter pool: PUS parameter values by id, cached from the interaction layer.

Every attribute the spacecraft database maps to a parameter ID is watched on the
interaction layer node; each publication refreshes the cache, which is what housekeeping
and service 20 read. A component that appears later, or comes back after a restart, is
subscribed again and its values are read again (``bind``, then ``follow`` or ``refresh``).
Sets go through the node to the component (``aset`` from asyncio handlers, ``set`` from
plain code), so the component stays the owner of its state.
Parameters of no component (the process's own counters) are served by getter functions.

With a context store (``persist``) every value set through the pool (service 20, and the
event-action and scheduled TCs that carry service 20 sets) is saved atomically under
``parameters`` and survives a restart: at start a saved value is the value of a parameter of
no component, goes to the setter of a process-local one when it is provided, and is set again
on a component each time the component (re)appears, before its values are read. A component
that restarts with its defaults thus gets the operators' settings back.
"""

from binascii import hexlify, unhexlify

from obsw.il.errors import InteractionError

STORE_NAME = "parameters"  # the context store's entry of the persisted values

_ZERO = {1: False, 2: 0, 3: 0, 4: 0, 5: 0.0, 6: 0, 7: b"", 8: ""}


class ParameterError(KeyError):
    """An unknown parameter ID, or a set that is not allowed; ``pid`` names it."""

    def __init__(self, msg, pid):
        super().__init__(msg)
        self.pid = pid


class ParameterPool:
    """Parameter values of ``sdb`` (see the module text); ``timeout`` bounds each call."""

    def __init__(self, sdb, node=None, timeout=1.0):
        self.sdb = sdb
        self.node = node
        self.timeout = timeout
        self.values = {}  # pid -> last known value
        self.updates = 0  # publications taken in
        self.unbound = []  # qualified names that could not be subscribed to
        self._getters = {}  # pid -> (getter, setter) of process-local parameters
        self._by_topic = {}
        self._subs = []
        self._routes = {}  # component -> the route its values were last read through
        self.reads = 0  # attribute reads of components that (re)appeared, by follow()
        self.store = None
        self.saved = {}  # pid -> value set through the pool, persisted with ``store``
        self.reapplied = 0  # saved values set again on components that (re)appeared
        self.rejected = 0  # saved values that could not be taken back
        for p in sdb.parameters.values():
            if p.component is not None:
                self._by_topic[(p.component, p.name)] = p.id

    def parameter(self, pid):
        p = self.sdb.parameters.get(pid)
        if p is None:
            raise ParameterError("no parameter %r" % (pid,), pid)
        return p

    def __contains__(self, pid):
        return pid in self.sdb.parameters

    def type_of(self, pid):
        """The packet field type of parameter ``pid`` (for deduced fields)."""
        return self.parameter(pid).type

    def provide(self, key, getter, setter=None):
        """Serve a parameter of no component with ``getter()`` (and ``setter(value)``)."""
        p = self.sdb.parameter(key)
        self._getters[p.id] = (getter, setter)
        if setter is not None and p.id in self.saved:
            try:
                setter(self.saved[p.id])
            except (ValueError, TypeError):
                self.rejected += 1
        return p.id

    # -------------------------------------------------------------------------- persistence

    def persist(self, store):
        """Save every value set from now on in ``store`` (``obsw.store.Store``) and take back
        what it holds (see the module text); returns how many values it held."""
        self.store = store
        saved = store.load(STORE_NAME) or {}
        if not isinstance(saved, dict):  # not what this writes: set aside, start clean
            self.rejected += 1
            saved = {}
            set_aside = getattr(store, "set_aside", None)
            if set_aside is not None:
                set_aside(STORE_NAME)
        for key, raw in saved.items():
            try:
                pid = int(key)
                p = self.parameter(pid)
                value = _decode(raw)
                p.type.check(value)
            except (ValueError, TypeError, KeyError):
                self.rejected += 1
                continue
            self.saved[pid] = value
            if p.component is None and pid not in self._getters:
                self.values[pid] = value
        return len(self.saved)

    def _remember(self, pid, value):
        if self.store is None:
            return
        self.saved[pid] = value
        self.store.save(STORE_NAME, dict((str(k), _encode(v)) for k, v in self.saved.items()))

    def _saved_of(self, comp):
        return [(pid, v) for pid, v in self.saved.items() if self.parameter(pid).component == comp]

    def bind(self):
        """Watch every component attribute on the node and read the current values of the
        components that are there now; return how many attributes were read.

        A component that is not there yet (it starts later) or that restarts is subscribed
        again by the node's transport when it appears; ``refresh`` (or the ``follow`` task)
        reads its values then, so PUS never keeps a frozen value of a component that came back.
        """
        if self.node is None:
            return 0
        if not self._subs:
            for comp, member in self._by_topic:
                self._subs.append(self.node.watch(comp + "." + member, self._published))
        return self.refresh()

    def _components(self):
        out = {}
        for (comp, member), pid in self._by_topic.items():
            out.setdefault(comp, []).append((comp + "." + member, pid))
        return out

    def appeared(self):
        """Components whose route is new since the last look (started, or restarted), and
        refresh ``unbound`` (attributes of components that are not there now)."""
        new = []
        self.unbound = []
        registry = self.node.registry
        for comp, attrs in self._components().items():
            route = registry.resolve(comp)
            if route is None:
                self._routes.pop(comp, None)
                self.unbound.extend(name for name, _ in attrs)
            elif self._routes.get(comp) is not route:
                self._routes[comp] = route
                new.append(comp)
        return new

    def _failed(self, comp, name):
        self._routes.pop(comp, None)  # read again at the next look
        self.unbound.append(name)

    def refresh(self):
        """Read the attributes of every component that (re)appeared (blocking calls)."""
        if self.node is None:
            return 0
        n = 0
        components = self._components()
        for comp in self.appeared():
            for pid, value in self._saved_of(comp):
                try:
                    self.node.set(self.parameter(pid).qualified, value, timeout=self.timeout)
                    self.reapplied += 1
                except InteractionError:
                    self.rejected += 1
            for name, pid in components[comp]:
                try:
                    self.values[pid] = self.node.get(name, timeout=self.timeout)
                    n += 1
                except InteractionError:
                    self._failed(comp, name)
        return n

    async def arefresh(self):
        """``refresh`` for asyncio tasks: the reads are awaited."""
        n = 0
        components = self._components()
        for comp in self.appeared():
            for pid, value in self._saved_of(comp):
                try:
                    qualified = self.parameter(pid).qualified
                    await self.node.aset(qualified, value, timeout=self.timeout)
                    self.reapplied += 1
                except InteractionError:
                    self.rejected += 1
            for name, pid in components[comp]:
                try:
                    self.values[pid] = await self.node.aget(name, timeout=self.timeout)
                    n += 1
                except InteractionError:
                    self._failed(comp, name)
        self.reads += n
        return n

    async def follow(self, period=0.25):
        """An asyncio task: every ``period`` seconds, read the components that (re)appeared."""
        import asyncio  # only here: boards without asyncio still import this module

        while True:
            await self.arefresh()
            await asyncio.sleep(period)

    def _published(self, pub):
        pid = self._by_topic.get((pub.component, pub.member))
        if pid is not None:
            self.values[pid] = pub.value
            self.updates += 1

    def get(self, pid):
        """The value of ``pid``: its getter's, the cached one, the default or zero."""
        local = self._getters.get(pid)
        if local is not None:
            return local[0]()
        v = self.values.get(pid)
        if v is not None:
            return v
        p = self.parameter(pid)
        if p.default is not None:  # an engineering value, like the range it lies in
            return p.default if p.values is None else p.to_raw(p.default)
        return _ZERO.get(p.type.ptc, 0)

    def _prepare(self, pid, value):
        p = self.parameter(pid)
        if not p.writable:
            raise ParameterError("parameter %s is read-only" % p.qualified, pid)
        p.type.check(value)
        return p

    def set(self, pid, value):
        """Set ``pid`` through its component (blocking call on the node) or its setter."""
        p = self._prepare(pid, value)
        local = self._getters.get(pid)
        if local is not None:
            if local[1] is None:
                raise ParameterError("parameter %s has no setter" % p.qualified, pid)
            local[1](value)
            self._remember(pid, value)
            return
        if self.node is None or p.component is None:
            self.values[pid] = value
            self._remember(pid, value)
            return
        self.node.set(p.qualified, value, timeout=self.timeout)
        self.values[pid] = value
        self._remember(pid, value)

    async def aset(self, pid, value):
        """``set`` for asyncio handlers: a remote component is awaited, not polled."""
        p = self._prepare(pid, value)
        if self._getters.get(pid) is not None or self.node is None or p.component is None:
            self.set(pid, value)
            return
        await self.node.aset(p.qualified, value, timeout=self.timeout)
        self.values[pid] = value
        self._remember(pid, value)

    def close(self):
        for s in self._subs:
            s.cancel()
        self._subs = []
        self._routes = {}


def _encode(value):
    """A value as JSON can keep it: octet strings as ``{"hex": ...}``."""
    if isinstance(value, (bytes, bytearray)):
        return {"hex": hexlify(value).decode()}
    return value


def _decode(raw):
    if isinstance(raw, dict):
        return bytes(unhexlify(raw["hex"]))
    return raw
