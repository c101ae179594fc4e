"""SpaceCAN packet fragmentation: [total-1][index][<=6 bytes] per frame, and robust reassembly.

The wire format is spacecan's; reassembly adds what it lacks: state per (bus, CAN id), reset on
index 0, the same total in every frame, contiguous indices, duplicates dropped, a timeout, and
counters for every frame thrown away.
"""

from obsw.compat import const, micropython

CHUNK = const(6)
MAX_FRAMES = const(256)
MAX_PACKET_SIZE = const(1536)  # 256 frames of 6 bytes


class PacketTooLongError(ValueError):
    """A packet longer than 256 fragments of 6 bytes can carry."""

    def __init__(self, length):
        super().__init__(
            "SpaceCAN packet too long: %d bytes, at most %d" % (length, MAX_PACKET_SIZE)
        )
        self.length = length


@micropython.native
def split(payload):
    """Return the frames' data (list of bytes) that carry payload; an empty one still gives one."""
    payload = bytes(payload)
    n = len(payload)
    if n > MAX_PACKET_SIZE:
        raise PacketTooLongError(n)
    if n <= CHUNK:
        return [b"\x00\x00" + payload]
    last = (n - 1) // CHUNK
    out = []
    i = 0
    while i <= last:
        out.append(bytes((last, i)) + payload[i * CHUNK : i * CHUNK + CHUNK])
        i += 1
    return out


def frame_count(length):
    """How many frames a packet of length bytes needs."""
    return (length + CHUNK - 1) // CHUNK or 1


COUNTERS = (
    "frames",  # fragments offered
    "packets",  # packets completed
    "short",  # frames under 2 bytes
    "bad_index",  # index beyond the announced total
    "stray",  # a continuation with no packet started
    "inconsistent",  # a total that differs from the packet's first frame
    "duplicates",  # an index already stored
    "gaps",  # an index that skips ahead: the partial packet is dropped
    "restarts",  # index 0 while a packet was in progress: the partial packet is dropped
    "timeouts",  # partial packets dropped after no fragment arrived for `timeout` seconds
)


class Reassembler:
    """Reassembles packets from fragments, one partial packet per key (e.g. (bus, can_id)).

    `push(key, data, now)` returns the packet's bytes when the last fragment arrives, else None.
    Nothing it is fed can make it stop delivering later packets: a stale partial packet is
    replaced by the next index 0 and expires after `timeout` seconds of silence.
    """

    def __init__(self, timeout=0.5):
        self.timeout = timeout
        self._partial = {}  # key -> [total, next_index, chunks, last_time]
        self.counters = {}
        for name in COUNTERS:
            self.counters[name] = 0

    def _count(self, name):
        self.counters[name] += 1

    @micropython.native
    def push(self, key, data, now):
        c = self.counters
        c["frames"] += 1
        if not self._partial and len(data) >= 2 and data[0] == 0 and data[1] == 0:
            c["packets"] += 1  # a packet of one frame, nothing pending: the usual request
            packet = data[2:]
            return packet if type(packet) is bytes else bytes(packet)
        if len(data) < 2:
            c["short"] += 1
            return None
        total = data[0] + 1
        index = data[1]
        partial = self._partial.get(key)
        if partial is not None and now - partial[3] > self.timeout:
            del self._partial[key]
            c["timeouts"] += 1
            partial = None
        if index >= total:
            c["bad_index"] += 1
            return None
        if index == 0:
            if partial is not None:
                del self._partial[key]
                c["restarts"] += 1
            if total == 1:
                c["packets"] += 1
                return bytes(data[2:])
            self._partial[key] = [total, 1, [bytes(data[2:])], now]
            return None
        if partial is None:
            c["stray"] += 1
            return None
        if total != partial[0]:
            c["inconsistent"] += 1
            return None
        expected = partial[1]
        if index < expected:
            c["duplicates"] += 1
            return None
        if index > expected:
            del self._partial[key]
            c["gaps"] += 1
            return None
        partial[2].append(bytes(data[2:]))
        partial[3] = now
        if index + 1 == total:
            del self._partial[key]
            c["packets"] += 1
            return b"".join(partial[2])
        partial[1] = index + 1
        return None

    def expire(self, now):
        """Drop partial packets silent for longer than the timeout; return how many."""
        if not self._partial:
            return 0  # the usual case, and one that allocates nothing
        stale = [k for k, p in self._partial.items() if now - p[3] > self.timeout]
        for k in stale:
            del self._partial[k]
            self.counters["timeouts"] += 1
        return len(stale)

    def next_deadline(self):
        """When the oldest partial packet expires (None if none is pending)."""
        best = None
        for p in self._partial.values():
            t = p[3] + self.timeout
            if best is None or t < best:
                best = t
        return best

    def pending(self):
        """Number of partial packets held."""
        return len(self._partial)

    def dropped(self):
        """Total frames or partial packets thrown away."""
        c = self.counters
        return sum(c[n] for n in COUNTERS[2:])
