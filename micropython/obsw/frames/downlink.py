"""The TM downlink at the radio's rate: frames handed out as the link frees, and a bounded
spill store for packets their virtual channel has no room for (never a silent drop)."""

from collections import deque

RESEND_RANGES = 16  # ranges the ground's resend requests may have waiting at once


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


class StoreForward:
    """Store-and-forward across passes: what the radio sends, when, and from which store.

    Every TM is kept in a packet store (``obsw.pus.services.packet_store``); ``stores`` lists
    them by priority, highest first. Out of contact nothing leaves. In contact ``next(now)``
    gives the next ``(store, seq, raw)`` to send: first the packets the ground asked for again
    (``resend``: gaps it saw in the storage sequence numbers), then each store's packets in
    sequence, in priority order, so real-time TM is the dump caught up with the present. A
    packet leaves only when it fits in what the pass can still carry (``budget`` octets, from
    the pass table's time left at ``bps``), so a dump is never cut at LOS: what does not fit
    waits for the next pass. The forwarder's pointer (``next_seq``, apart from the stores'
    ST[15] open retrieval, which stays the operator's) never goes back, and the ground's
    acknowledgement (``acknowledge``) deletes what it has, so nothing is sent twice and
    nothing is dropped while the stores have room.
    """

    def __init__(self, stores, contact, bps):
        self.stores = list(stores)
        self.contact = contact
        self.bps = bps
        self.sent = 0  # packets
        self.sent_octets = 0
        self.resent = 0
        self.held = 0  # packets that waited for the next pass (did not fit in this one)
        self._resend = deque((), RESEND_RANGES)  # [store, next seq, last seq]: ranges asked
        # the next storage sequence number to send, per store: the forwarder's own pointer
        # (the stores' ST[15] open retrieval stays the operator's, apart from it)
        self.next_seq = {}
        for st in self.stores:
            self.next_seq[st.id] = 1

    def store(self, sid):
        for st in self.stores:
            if st.id == sid:
                return st
        raise KeyError("no packet store %d" % sid)

    def budget(self, now):
        """Octets the radio can still send in this contact (its time left at the rate)."""
        return self.contact.left(now) * self.bps / 8

    def resend(self, sid, first, last):
        """The ground lacks storage sequence numbers ``first`` to ``last`` of store ``sid``
        (a range of any length: each packet still kept goes again, in order); False when
        ``RESEND_RANGES`` ranges are already waiting (it asks again)."""
        st = self.store(sid)
        if first > last:
            return True
        if len(self._resend) >= RESEND_RANGES:
            return False
        self._resend.append([st, first, last])
        return True

    def acknowledge(self, sid, seq):
        """The ground has everything of store ``sid`` up to ``seq``: the room is free again."""
        return self.store(sid).delete_through(seq)

    def next(self, now, budget=None):
        """The next ``(store, seq, raw)`` to send now, or None (out of contact, nothing to
        send, or the next packet does not fit in ``budget`` octets: default ``budget(now)``)."""
        if not self.contact.contact(now):
            return None
        room = self.budget(now) if budget is None else budget
        while self._resend:
            r = self._resend[0]
            st = r[0]
            i = _first_at(st.packets, r[1])
            if i == len(st.packets) or st.packets[i][0] > r[2]:  # sent, or deleted since
                self._resend.popleft()
                continue
            seq, _t, raw = st.packets[i]
            if len(raw) > room:
                self.held += 1
                return None
            r[1] = seq + 1
            self.resent += 1
            return self._out(st, seq, raw)
        for st in self.stores:
            i = _first_at(st.packets, self.next_seq[st.id])
            if i < len(st.packets):
                seq, _t, raw = st.packets[i]
                if len(raw) > room:
                    self.held += 1
                    return None  # the highest priority first: lower ones wait behind it
                self.next_seq[st.id] = seq + 1
                return self._out(st, seq, raw)
        return None

    def _out(self, st, seq, raw):
        self.sent += 1
        self.sent_octets += len(raw)
        return st, seq, raw

    def backlog(self):
        """Octets stored and not yet sent, over all stores."""
        n = 0
        for st in self.stores:
            packets = st.packets
            for i in range(_first_at(packets, self.next_seq[st.id]), len(packets)):
                n += len(packets[i][2])
        return n


def _first_at(packets, seq):
    """The index of the first of ``packets`` (``[seq, time, raw]``, in storage order) whose
    storage sequence number is ``seq`` or later (``len(packets)`` if none)."""
    lo, hi = 0, len(packets)
    while lo < hi:
        mid = (lo + hi) // 2
        if packets[mid][0] < seq:
            lo = mid + 1
        else:
            hi = mid
    return lo
