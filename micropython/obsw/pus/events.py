"""The event manager: component events on the interaction layer become PUS events.

It subscribes to every component event the spacecraft database lists, looks up the event's
PUS ID and severity, packs its payload as the auxiliary data the database declares, and
hands ``(event_id, severity, aux)`` to its listeners (the application process, whose event
reporting service decides what goes to ground). Events of no component (the process's own,
such as a cycle overrun) are raised with ``raise_event``.
"""

from obsw.il.errors import InteractionError


class EventManager:
    def __init__(self, sdb, node=None, timeout=1.0):
        self.sdb = sdb
        self.node = node
        self.timeout = timeout
        self.listeners = []  # callables(event_id, severity, aux)
        self.raised = 0
        self.bad_payloads = 0  # payloads that did not fit the declared layout (sent empty)
        self.unbound = []
        self._subs = []

    def connect(self, app):
        """Deliver events to an ApplicationProcess (its ``event`` method)."""
        self.listeners.append(app.event)

    def bind(self):
        """Watch every component event of the database on the node: a component that starts
        later, or restarts, is subscribed (again) when it appears."""
        if self.node is None:
            return 0
        n = 0
        self.unbound = []
        for ev in self.sdb.events.values():
            if ev.component is None:
                continue
            try:
                self._subs.append(self.node.watch(ev.qualified, self._published))
                n += 1
            except InteractionError:  # an event the (local) component does not have
                self.unbound.append(ev.qualified)
        return n

    def _published(self, pub):
        try:
            ev = self.sdb.event(pub.component + "." + pub.member)
        except KeyError:
            return
        self._raise(ev, pub.value)

    def raise_event(self, key, payload=None):
        """Raise the event with this ID or qualified name; returns its PUS event ID."""
        ev = self.sdb.event(key)
        self._raise(ev, payload)
        return ev.id

    def _raise(self, ev, payload):
        try:
            aux = ev.pack(payload) if payload is not None else b""
        except (ValueError, TypeError, KeyError):
            self.bad_payloads += 1
            aux = b""
        self.raised += 1
        for fn in self.listeners:
            fn(ev.id, ev.severity, aux)

    def close(self):
        for s in self._subs:
            s.cancel()
        self._subs = []
