"""Clocks the interaction layer is given: the real one and a simulated one for tests."""

from obsw.compat import monotonic, sleep


class RealClock:
    """Wall-clock seconds from ``compat.monotonic``; ``sleep`` really sleeps."""

    def now(self):
        return monotonic()

    def sleep(self, seconds):
        """Block up to ``seconds`` in slices of a millisecond, so a waiter re-checks often."""
        if seconds > 0:
            sleep(seconds if seconds < 0.001 else 0.001)


class SimClock:
    """Simulated seconds: time moves only when ``advance`` or ``sleep`` is called.

    ``call_at``/``call_later`` schedule functions that run, in time order, while time passes
    over them; a test uses them to play a producer, a consumer or a restarting provider.
    """

    def __init__(self, start=0.0):
        self._now = start
        self._timers = []  # sorted (when, seq, fn)
        self._seq = 0

    def now(self):
        return self._now

    def call_at(self, when, fn):
        self._seq += 1
        entry = (when, self._seq, fn)
        timers = self._timers
        i = len(timers)
        while i > 0 and (timers[i - 1][0], timers[i - 1][1]) > (when, self._seq):
            i -= 1
        timers.insert(i, entry)
        return entry

    def call_later(self, delay, fn):
        return self.call_at(self._now + delay, fn)

    def cancel(self, entry):
        if entry in self._timers:
            self._timers.remove(entry)

    def pending(self):
        """Number of scheduled functions not yet run."""
        return len(self._timers)

    def advance(self, seconds):
        """Move time forward by ``seconds``, running every function that falls due on the way."""
        end = self._now + seconds
        timers = self._timers
        while timers and timers[0][0] <= end:
            when, _, fn = timers.pop(0)
            if when > self._now:
                self._now = when
            fn()
        if end > self._now:
            self._now = end

    def sleep(self, seconds):
        """What a blocked caller does on simulated time: let the simulated world run.

        Like a blocked task woken by an event, it returns early once scheduled functions have
        run, so the caller can re-check its condition; otherwise it moves the full span.
        """
        end = self._now + (seconds if seconds > 0 else 0)
        timers = self._timers
        if timers and timers[0][0] <= end:
            when = timers[0][0]
            if when > self._now:
                self._now = when
            while timers and timers[0][0] <= when:
                timers.pop(0)[2]()
        else:
            self._now = end


REAL_CLOCK = RealClock()
