"""Drop the second copy of a frame that arrives on both of two hot-redundant links."""

from collections import deque


class Deduplicator:
    """Pairs identical frames arriving on different links within ``window`` seconds.

    ``duplicate(key, link, now)`` is True for the copy that completes a pair (drop it). A frame
    repeated on the same link (a retransmission) is never a duplicate of itself.
    """

    def __init__(self, window=2.0, depth=64):
        self.window = window
        self.depth = depth  # frames remembered at most (the oldest forgotten first)
        self._recent = deque((), depth + 1)
        self._index = {}  # key -> its entries in _recent: a lookup, not a scan
        self.dropped = 0

    def _forget(self):
        old = self._recent.popleft()
        entries = self._index.get(old[0])
        if entries is not None:
            entries.remove(old)
            if not entries:
                del self._index[old[0]]

    def duplicate(self, key, link, now):
        recent = self._recent
        while recent and (now - recent[0][2] > self.window or len(recent) >= self.depth):
            self._forget()
        entries = self._index.get(key)
        if entries is not None:
            for entry in entries:
                if entry[1] != link and entry[3]:
                    entry[3] = False  # each copy pairs once
                    self.dropped += 1
                    return True
        entry = [key, link, now, True]
        recent.append(entry)
        if entries is None:
            self._index[key] = [entry]
        else:
            entries.append(entry)
        return False
