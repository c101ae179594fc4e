"""TM to every ground client: the set of UDP addresses an on-board process sends its TM to.

A ground client subscribes by sending anything to the on-board port: a TC, or the short
datagram ``SUBSCRIBE`` (a listener that sends no TC repeats it every ``linger / 3`` seconds).
A client silent for ``linger`` seconds is dropped; ``UNSUBSCRIBE`` drops it at once. Addresses
given as ``static`` (the frame processor's TM input, a configured ground station) always
receive TM. Neither control datagram can be a space packet (those are at least 7 bytes long).
"""

import time

SUBSCRIBE = b"sub"
UNSUBSCRIBE = b"unsub"
LINGER = 60.0  # seconds a silent client keeps receiving TM


class TmFanout:
    """Who receives TM: static addresses and live subscribers (see the module text)."""

    def __init__(self, static=(), linger=LINGER, clock=time.monotonic):
        self.static = [tuple(a) for a in static if a is not None]
        self.linger = linger
        self.clock = clock
        self.subscribers = {}  # address -> last time heard

    def heard(self, data, address):
        """Note a datagram from ``address``; True if it is a TC for the process to handle."""
        if data == UNSUBSCRIBE:
            self.subscribers.pop(address, None)
            return False
        self.subscribers[address] = self.clock()
        return data != SUBSCRIBE

    def targets(self):
        """The addresses TM goes to now (silent subscribers dropped)."""
        now = self.clock()
        for address, last in list(self.subscribers.items()):
            if now - last > self.linger:
                del self.subscribers[address]
        out = list(self.static)
        out.extend(a for a in self.subscribers if a not in out)
        return out

    def send(self, sendto, raw):
        """Send ``raw`` with ``sendto(raw, address)`` to every target; returns how many."""
        targets = self.targets()
        for address in targets:
            sendto(raw, address)
        return len(targets)
