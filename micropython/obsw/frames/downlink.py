"""The TM downlink at the radio's rate: frames handed out as the link frees, and a bounded
spill store for packets their virtual channel has no room for (never a silent drop)."""

from collections import deque


class Downlink:
    """Pacing of a link of ``bps`` bit/s whose frames are ``frame_octets`` channel octets.

    ``due(now)`` is how many frames to hand the radio now: enough that it always holds
    ``lead`` frames beyond the one it is sending, never more, so a frame chosen now waits at
    most ``lead`` frame times (live telemetry keeps its latency behind a long playback). A
    link left without frames saves no credit. ``frame_time`` is one frame's time on the air.
    """

    def __init__(self, bps, frame_octets, lead=1):
        if bps <= 0:
            raise ValueError("downlink rate %r bit/s; expected a positive rate" % (bps,))
        self.bps = bps
        self.frame_octets = frame_octets
        self.frame_time = frame_octets * 8 / bps
        self.lead = lead
        self.frames = 0
        self._free_at = None  # when the radio will have sent every frame handed to it

    def due(self, now):
        if self._free_at is None or self._free_at < now:
            self._free_at = now
        n = 0
        horizon = now + (self.lead + 1) * self.frame_time
        while self._free_at + self.frame_time <= horizon + 1e-9:
            self._free_at += self.frame_time
            n += 1
        self.frames += n
        return n


class Spill:
    """Packets waiting for room in their virtual channel, at most ``capacity`` octets in all.

    ``put(vcid, packet)`` keeps a packet (False when full: the caller reports it);
    ``refill(mux)`` moves what now fits back into the channels, in order. ``waiting(vcid)``
    says whether a channel has spilled packets (later ones must queue behind them)."""

    def __init__(self, capacity):
        self.capacity = capacity
        self.octets = 0
        self.spilled = 0
        self._queues = {}

    def waiting(self, vcid):
        q = self._queues.get(vcid)
        return bool(q)

    def put(self, vcid, packet):
        if self.octets + len(packet) > self.capacity:
            return False
        q = self._queues.get(vcid)
        if q is None:
            q = self._queues[vcid] = deque((), self.capacity // 7 + 1)  # 7: the shortest packet
        q.append(packet)
        self.octets += len(packet)
        self.spilled += 1
        return True

    def refill(self, mux):
        for vcid, q in self._queues.items():
            channel = mux.channel(vcid)
            while q and channel.room() >= len(q[0]):
                packet = q.popleft()
                channel.push(packet)
                self.octets -= len(packet)
