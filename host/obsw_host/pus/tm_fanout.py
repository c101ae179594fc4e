"""TM to every ground client: the set of UDP addresses an on-board process sends its TM to.

A ground client subscribes by sending anything to the on-board port: a TC, or the short
datagram ``SUBSCRIBE`` (a listener that sends no TC repeats it every ``linger / 3`` seconds).
A client silent for ``linger`` seconds is dropped; ``UNSUBSCRIBE`` drops it at once. Addresses
given as ``static`` (the frame processor's TM input, a configured ground station) always
receive TM. Neither control datagram can be a space packet (those are at least 7 bytes long).

At most ``limit`` subscribers (``MAX_SUBSCRIBERS``) are kept. When the set is full, silent ones
are dropped first; then a new address that only sends ``SUBSCRIBE`` is refused (counted in
``refused``), while one that sends a TC takes the place of the client heard least recently (it
gets its replies). A flood of datagrams from many ports neither grows the set nor keeps an
operator who sends a TC from being answered.
"""

import time

SUBSCRIBE = b"sub"
UNSUBSCRIBE = b"unsub"
LINGER = 60.0  # seconds a silent client keeps receiving TM
MAX_SUBSCRIBERS = 16  # ground clients receiving TM at once (docs/hardening.md)


class TmFanout:
    """Who receives TM: static addresses and live subscribers (see the module text)."""

    def __init__(self, static=(), linger=LINGER, clock=time.monotonic, limit=MAX_SUBSCRIBERS):
        self.static = [tuple(a) for a in static if a is not None]
        self.linger = linger
        self.clock = clock
        self.limit = limit
        self.subscribers = {}  # address -> last time heard
        self.refused = 0  # new subscribers refused while the set was full
        self._targets = None  # what ``targets`` returns until the set changes
        self._due = None  # no subscriber falls silent before then (None: none to prune)

    def heard(self, data, address):
        """Note a datagram from ``address``; True if it is a TC for the process to handle."""
        if data == UNSUBSCRIBE:
            if self.subscribers.pop(address, None) is not None:
                self._targets = None
            return False
        subs = self.subscribers
        now = self.clock()
        tc = data != SUBSCRIBE
        if address in subs:  # a known client (every TC of an operator): kept fresh
            subs[address] = now
            return tc
        if len(subs) >= self.limit:
            self._prune(now)
            if len(subs) >= self.limit:
                self.refused += 1
                if not tc:
                    return False
                oldest = min(subs, key=subs.get)
                del subs[oldest]
        self._targets = None
        if self._due is None or now + self.linger < self._due:
            self._due = now + self.linger
        subs[address] = now
        return tc

    def _prune(self, now):
        due = None
        for address, last in list(self.subscribers.items()):
            if now - last > self.linger:
                del self.subscribers[address]
                self._targets = None
            elif due is None or last + self.linger < due:
                due = last + self.linger
        self._due = due

    def targets(self):
        """The addresses TM goes to now (silent subscribers dropped); the same list until
        the set changes (not to be changed by the caller)."""
        due = self._due
        if due is not None and self.clock() > due:
            self._prune(self.clock())
        out = self._targets
        if out is None:
            out = list(self.static)
            out.extend(a for a in self.subscribers if a not in out)
            self._targets = out
        return out

    def send(self, sendto, raw):
        """Send ``raw`` with ``sendto(raw, address)`` to every target; returns how many."""
        targets = self.targets()
        for address in targets:
            sendto(raw, address)
        return len(targets)
