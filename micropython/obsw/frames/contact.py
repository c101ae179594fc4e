"""Contact with the ground, as the spacecraft knows it: from the link and from a pass table.

The link says so directly: a TC frame accepted, the CLCW's lock or the radio's carrier
indication (``heard(now)``; ``carrier(on, now)`` for a radio that reports its carrier). The
pass table (``load(windows)``: ``[(aos, los), ..]`` in onboard seconds, uplinked by the ground
from its pass prediction) says when a pass is due, so the transmitter and the dump can start at
AOS before the first TC, and how much a pass can still carry (``left(now)``).

``update(now)`` is polled by the owner's loop and returns the edge it crossed: ``AOS``,
``LOS`` or None. In contact means: the carrier is on, or a frame was heard within ``hold``
seconds, or ``now`` is inside a window of the table.
"""

from obsw.compat import const

AOS = "aos"
LOS = "los"
MAX_WINDOWS = const(64)  # a week of passes over three stations fits


class PassTableError(ValueError):
    """A pass table that cannot be loaded; the message says what was expected."""


class Contact:
    """Contact state (see the module text); time is passed in, onboard seconds."""

    def __init__(self, hold=10.0):
        self.hold = hold
        self.windows = []  # [(aos, los)], by AOS, disjoint
        self.last_heard = None
        self.carrier_on = False
        self.in_contact = False
        self.aos_count = 0
        self.since = None  # when the current state began

    def load(self, windows):
        """Replace the pass table; windows must be ordered, disjoint, each AOS before its LOS."""
        ws = [(float(a), float(b)) for a, b in windows]
        if len(ws) > MAX_WINDOWS:
            raise PassTableError("%d passes; expected at most %d" % (len(ws), MAX_WINDOWS))
        for i in range(len(ws)):
            a, b = ws[i]
            if not a < b:
                raise PassTableError("pass %d AOS %.3f not before LOS %.3f" % (i, a, b))
            if i and a < ws[i - 1][1]:
                text = "pass %d starts %.3f before pass %d ends %.3f" % (i, a, i - 1, ws[i - 1][1])
                raise PassTableError(text + "; expected ordered, disjoint passes")
        self.windows = ws

    def heard(self, now):
        """The link was heard now (a TC frame accepted, the CLCW locked)."""
        self.last_heard = now

    def carrier(self, on, now):
        self.carrier_on = bool(on)
        if on:
            self.last_heard = now

    def window(self, now):
        """The pass table's window that holds ``now``, or None."""
        for a, b in self.windows:
            if a <= now < b:
                return (a, b)
            if a > now:
                break
        return None

    def next_window(self, now):
        """The first window that ends after ``now``, or None."""
        for a, b in self.windows:
            if b > now:
                return (a, b)
        return None

    def left(self, now):
        """Seconds of contact left by the table (the current window's LOS - now); the hold
        when only the link says so; 0 out of contact."""
        w = self.window(now)
        if w is not None:
            return w[1] - now
        return self.hold if self.contact(now) else 0.0

    def contact(self, now):
        if self.carrier_on:
            return True
        if self.last_heard is not None and now - self.last_heard < self.hold:
            return True
        return self.window(now) is not None

    def update(self, now):
        """The edge crossed since the last call: AOS, LOS or None."""
        c = self.contact(now)
        if c == self.in_contact:
            return None
        self.in_contact = c
        self.since = now
        # windows in the past are of no more use
        while self.windows and self.windows[0][1] <= now:
            self.windows.pop(0)
        if c:
            self.aos_count += 1
            return AOS
        return LOS
