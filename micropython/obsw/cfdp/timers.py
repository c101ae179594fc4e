"""CFDP timers: a deadline and an expiry counter; time is always passed in (seconds)."""


class Timer:
    """Deadline-based timer with a count of expiries; ``limit`` is how many are tolerated."""

    def __init__(self, interval, limit=0):
        self.interval = interval
        self.limit = limit
        self.deadline = None
        self.count = 0
        self._left = None  # remaining time while suspended
        self._held = False  # suspended: a start waits for the resume

    def start(self, now, reset_count=False):
        if self._held:  # started while its transaction is suspended: runs from the resume
            self.deadline = None
            self._left = self.interval
        else:
            self.deadline = None if self.interval is None else now + self.interval
            self._left = None
        if reset_count:
            self.count = 0

    def stop(self):
        self.deadline = None
        self._left = None

    @property
    def running(self):
        return self.deadline is not None

    def expired(self, now):
        return self.deadline is not None and now >= self.deadline

    def expire(self, now):
        """Count an expiry and restart; True when the count has passed the limit."""
        self.count += 1
        self.start(now)
        return self.count > self.limit

    def suspend(self, now):
        """Freeze: what is left waits for ``resume``, and so does a ``start`` meanwhile (a PDU
        that arrives while the transaction is suspended moves no timer on)."""
        if self.deadline is not None:
            self._left = max(0, self.deadline - now)
            self.deadline = None
        self._held = True

    def resume(self, now):
        self._held = False
        if self._left is not None:
            self.deadline = now + self._left
            self._left = None

    def state(self):
        return [self.count, self.deadline is not None or self._left is not None]

    def restore(self, st, now):
        self.count = st[0]
        if st[1]:
            self.start(now)
