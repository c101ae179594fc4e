"""Bounded FIFO queues with FreeRTOS xQueue semantics, for plain code and for asyncio tasks.

A ``Queue`` has a fixed length set at creation and pre-allocated slots. Items are copied in
(a ``bytearray``, ``list`` or ``dict`` is shallow-copied on the way in, a ``memoryview`` is
turned into ``bytes``), so the sender may reuse its buffer at once. Every operation takes a
timeout in seconds: ``0`` polls, ``FOREVER`` (``None``) waits without limit. "Full" and
"empty" are results, never exceptions: senders get ``True``/``False``, receivers get the item
or ``EMPTY``.

Blocking in plain code waits on the queue's clock (``clock.sleep`` may return early; the
queue re-checks), so on a simulated clock the test decides what happens meanwhile. The
``a``-prefixed coroutines wait on ``asyncio.Event`` and the event loop's own time; they work
on CPython and on MicroPython, whose asyncio has no queue.

``put`` applies the input's declared full policy: ``BLOCK`` (wait up to ``timeout`` given at
creation), ``DROP_NEWEST`` (refuse the new item) or ``OVERWRITE_OLDEST`` (discard the oldest).
Items that did not get in, or were pushed out, are counted in ``dropped``.
"""

from obsw.compat import const, ticks_diff, ticks_ms
from obsw.il.clock import REAL_CLOCK

FOREVER = None

BLOCK = const(0)
DROP_NEWEST = const(1)
OVERWRITE_OLDEST = const(2)
_POLICY_NAMES = ("block", "drop-newest", "overwrite-oldest")


class _Empty:
    def __repr__(self):
        return "EMPTY"

    def __bool__(self):
        return False


EMPTY = _Empty()


def policy_name(policy):
    return _POLICY_NAMES[policy]


def _copy_in(item):
    t = type(item)
    if t is bytearray or t is list or t is dict:
        return t(item)
    if t is memoryview:
        return bytes(item)
    return item


class Queue:
    """A fixed-length queue; see the module text for the semantics."""

    def __init__(self, length, policy=BLOCK, timeout=0, *, clock=None, copy=True, name=None):
        if not isinstance(length, int) or length < 1:
            raise ValueError("queue length must be a positive int, got %r" % (length,))
        if policy not in (BLOCK, DROP_NEWEST, OVERWRITE_OLDEST):
            raise ValueError("unknown queue full policy %r" % (policy,))
        self.length = length
        self.policy = policy
        self.timeout = timeout  # what put() waits under the BLOCK policy
        self.name = name
        self.dropped = 0
        self.clock = clock if clock is not None else REAL_CLOCK
        self._copy = copy
        self._slots = [None] * length
        self._head = 0  # slot of the oldest item
        self._count = 0
        self._readable = None  # asyncio.Event, made on first asynchronous use
        self._writable = None

    def __repr__(self):
        return "Queue(%s%d/%d, %s, dropped=%d)" % (
            (self.name + ": ") if self.name else "",
            self._count,
            self.length,
            _POLICY_NAMES[self.policy],
            self.dropped,
        )

    # -------------------------------------------------------------------------- state

    def messages_waiting(self):
        return self._count

    def spaces_available(self):
        return self.length - self._count

    def __len__(self):
        return self._count

    def is_empty(self):
        return self._count == 0

    def is_full(self):
        return self._count == self.length

    def reset(self):
        """Empty the queue (xQueueReset); the drop counter is kept."""
        for i in range(self.length):
            self._slots[i] = None
        self._head = 0
        self._count = 0
        if self._writable is not None:
            self._writable.set()

    # -------------------------------------------------------------------------- primitives

    def _push_back(self, item):
        if self._copy:
            item = _copy_in(item)
        i = self._head + self._count
        if i >= self.length:
            i -= self.length
        self._slots[i] = item
        self._count += 1
        if self._readable is not None:
            self._readable.set()

    def _push_front(self, item):
        if self._copy:
            item = _copy_in(item)
        h = self._head - 1
        if h < 0:
            h = self.length - 1
        self._head = h
        self._slots[h] = item
        self._count += 1
        if self._readable is not None:
            self._readable.set()

    def _pop(self):
        h = self._head
        item = self._slots[h]
        self._slots[h] = None
        h += 1
        self._head = 0 if h == self.length else h
        self._count -= 1
        if self._writable is not None:
            self._writable.set()
        return item

    def _block(self, ready, timeout):
        """Wait on the clock until ``ready()`` or the timeout; return ``ready()``."""
        clock = self.clock
        if timeout is None:
            while not ready():
                clock.sleep(1.0)
            return True
        deadline = clock.now() + timeout
        while True:
            if ready():
                return True
            left = deadline - clock.now()
            if left <= 0:
                return False
            clock.sleep(left)

    def _has_space(self):
        return self._count < self.length

    def _has_item(self):
        return self._count > 0

    # -------------------------------------------------------------------------- plain code

    def send(self, item, timeout=0):
        """Append ``item`` (xQueueSendToBack); False if still full when the timeout ends."""
        if self._count < self.length or (timeout != 0 and self._block(self._has_space, timeout)):
            self._push_back(item)
            return True
        return False

    def send_to_front(self, item, timeout=0):
        """Put ``item`` first in line (xQueueSendToFront); False if full."""
        if self._count < self.length or (timeout != 0 and self._block(self._has_space, timeout)):
            self._push_front(item)
            return True
        return False

    def overwrite(self, item):
        """Write even when full (xQueueOverwrite); only for length-1 mailboxes."""
        if self.length != 1:
            raise ValueError("overwrite() is for length-1 queues; this one holds %d" % self.length)
        if self._count:
            self._pop()
        self._push_back(item)
        return True

    def receive(self, timeout=0):
        """Take the oldest item (xQueueReceive); ``EMPTY`` if none came in time."""
        if self._count or (timeout != 0 and self._block(self._has_item, timeout)):
            return self._pop()
        return EMPTY

    def peek(self, timeout=0):
        """Look at the oldest item without taking it (xQueuePeek); ``EMPTY`` if none."""
        if self._count or (timeout != 0 and self._block(self._has_item, timeout)):
            return self._slots[self._head]
        return EMPTY

    def put(self, item):
        """Send under the queue's declared full policy; return True if ``item`` is queued."""
        if self._count < self.length:
            self._push_back(item)
            return True
        policy = self.policy
        if policy == OVERWRITE_OLDEST:
            self._pop()
            self.dropped += 1
            self._push_back(item)
            return True
        if policy == BLOCK and self.timeout != 0 and self._block(self._has_space, self.timeout):
            self._push_back(item)
            return True
        self.dropped += 1
        return False

    # -------------------------------------------------------------------------- asyncio

    async def _await(self, which, ready, timeout):
        import asyncio  # only here: boards without asyncio still import this module

        if ready():
            return True
        if timeout == 0:
            return False
        if which == 0:
            if self._readable is None:
                self._readable = asyncio.Event()
            ev = self._readable
        else:
            if self._writable is None:
                self._writable = asyncio.Event()
            ev = self._writable
        start = ticks_ms()
        while True:
            ev.clear()
            if ready():
                return True
            if timeout is None:
                await ev.wait()
            else:
                left = timeout - ticks_diff(ticks_ms(), start) / 1000
                if left <= 0:
                    return ready()
                try:
                    await asyncio.wait_for(ev.wait(), left)
                except asyncio.TimeoutError:
                    return ready()

    async def asend(self, item, timeout=FOREVER):
        """``send`` for asyncio tasks: waits without blocking the event loop."""
        if await self._await(1, self._has_space, timeout):
            self._push_back(item)
            return True
        return False

    async def asend_to_front(self, item, timeout=FOREVER):
        if await self._await(1, self._has_space, timeout):
            self._push_front(item)
            return True
        return False

    async def areceive(self, timeout=FOREVER):
        """``receive`` for asyncio tasks; ``EMPTY`` on timeout."""
        if await self._await(0, self._has_item, timeout):
            return self._pop()
        return EMPTY

    async def apeek(self, timeout=FOREVER):
        if await self._await(0, self._has_item, timeout):
            return self._slots[self._head]
        return EMPTY

    async def aput(self, item):
        """``put`` for asyncio tasks: the BLOCK policy waits on the event loop."""
        if self.policy == BLOCK and self._count >= self.length and self.timeout != 0:
            if await self._await(1, self._has_space, self.timeout):
                self._push_back(item)
                return True
            self.dropped += 1
            return False
        return self.put(item)
