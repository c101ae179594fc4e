"""Drop the second copy of a frame that arrives on both of two hot-redundant links."""

from collections import deque


class Deduplicator:
    """Pairs identical frames arriving on different links within ``window`` seconds.

    ``duplicate(key, link, now)`` is True for the copy that completes a pair (drop it). A frame
    repeated on the same link (a retransmission) is never a duplicate of itself.
    """

    def __init__(self, window=2.0, depth=64):
        self.window = window
        self._recent = deque((), depth)
        self.dropped = 0

    def duplicate(self, key, link, now):
        recent = self._recent
        while recent and now - recent[0][2] > self.window:
            recent.popleft()
        for entry in recent:
            if entry[0] == key and entry[1] != link and entry[3]:
                entry[3] = False  # each copy pairs once
                self.dropped += 1
                return True
        recent.append([key, link, now, True])
        return False
