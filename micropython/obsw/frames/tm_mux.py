"""Packets into TM frames: virtual channels by configuration, multiplexed by priority."""

from obsw.compat import const
from obsw.frames.tm import FHP_IDLE, FHP_NO_PACKET, TmFrame
from obsw.spp import idle_packet

_IDLE_MIN = const(7)  # the shortest space packet: 6-byte header and one data byte


class TmVirtualChannel:
    """One TM virtual channel carrying space packets; a packet may span frames.

    Packets are queued as one byte stream with the offsets where packets start; each frame
    takes the next ``data_length`` bytes and its first header pointer is the first start in
    them. ``capacity`` bounds the queued bytes; ``push`` returns False and counts a drop when
    a packet does not fit.
    """

    def __init__(self, vcid, priority=0, capacity=16384, name=None):
        self.vcid = vcid
        self.priority = priority
        self.capacity = capacity
        self.name = name or "VC%d" % vcid
        self.count = 0  # virtual channel frame count of the next frame
        self.dropped = 0
        self.packets = 0
        self._buf = b""
        self._starts = []

    def push(self, packet):
        if len(self._buf) + len(packet) > self.capacity:
            self.dropped += 1
            return False
        self._starts.append(len(self._buf))
        self._buf += bytes(packet)
        self.packets += 1
        return True

    def pending(self):
        return len(self._buf)

    def room(self):
        """Octets a packet may have to be queued now."""
        return self.capacity - len(self._buf)

    def pad(self, data_length):
        """Complete a partly filled frame with an idle packet (it may spill into the next)."""
        r = len(self._buf) % data_length
        if r:
            n = data_length - r
            self._starts.append(len(self._buf))
            self._buf += idle_packet(n if n >= _IDLE_MIN else _IDLE_MIN).pack()

    def take(self, data_length):
        """The next frame's data field and first header pointer, or None if not a full frame."""
        if len(self._buf) < data_length:
            return None
        data = self._buf[:data_length]
        self._buf = self._buf[data_length:]
        starts = self._starts
        fhp = FHP_NO_PACKET
        k = 0
        while k < len(starts) and starts[k] < data_length:
            if k == 0:
                fhp = starts[0]
            k += 1
        self._starts = [s - data_length for s in starts[k:]]
        return data, fhp


class TmMultiplexer:
    """The master channel: picks virtual channels by priority, numbers and closes frames.

    ``ocf`` is a callable returning the 4-byte operational control field (the CLCW) or None for
    frames without one. ``frame(flush, idle)`` returns the next TmFrame: a full frame from the
    highest-priority channel that has one; with ``flush`` a partly filled channel is padded
    with an idle packet (with ``urgent`` only channels of that priority or higher are); with
    ``idle`` and nothing to send, an only-idle-data frame on ``idle_vcid``. Otherwise None.

    With ``security`` (an ``obsw.frames.sdls_gcm.TmSecurity``) the frames of each VC that has
    an SA carry SDLS: the packets fill the data field less the security header and trailer,
    and the field is protected (encrypted and authenticated) as the frame is closed.
    """

    def __init__(
        self,
        scid,
        frame_length,
        channels,
        ocf=None,
        fecf=True,
        idle_vcid=7,
        idle_pattern=b"\x55",
        security=None,
    ):
        self.scid = scid
        self.frame_length = frame_length
        self.channels = sorted(channels, key=lambda c: -c.priority)
        self.ocf = ocf
        self.fecf = fecf
        self.idle_vcid = idle_vcid
        self.idle_pattern = idle_pattern
        self.security = security
        self.mc_count = 0
        self.idle_count = 0
        self.frames = 0
        self.data_length = frame_length - 6 - (4 if ocf is not None else 0) - (2 if fecf else 0)
        if self.data_length < _IDLE_MIN:
            raise ValueError("TM frame length %d leaves no room for packets" % frame_length)
        self._by_id = {}
        for c in self.channels:
            self._by_id[c.vcid] = c

    def channel(self, vcid):
        return self._by_id[vcid]

    def pending(self):
        return sum(c.pending() for c in self.channels)

    def _room(self, vcid):
        if self.security is None:
            return self.data_length
        return self.data_length - self.security.overhead(vcid)

    def frame(self, flush=False, idle=False, urgent=None):
        for c in self.channels:
            d = self._room(c.vcid)
            got = c.take(d)
            pad = flush and (urgent is None or c.priority >= urgent)
            if got is None and pad and c.pending():
                c.pad(d)
                got = c.take(d)
            if got is not None:
                f = self._close(c.vcid, c.count, got[0], got[1])
                c.count = (c.count + 1) & 0xFF
                return f
        if idle:
            d = self._room(self.idle_vcid)
            pattern = (self.idle_pattern * (d // len(self.idle_pattern) + 1))[:d]
            f = self._close(self.idle_vcid, self.idle_count, pattern, FHP_IDLE)
            self.idle_count = (self.idle_count + 1) & 0xFF
            return f
        return None

    def _close(self, vcid, vc_count, data, fhp):
        ocf = self.ocf() if self.ocf is not None else None
        if self.ocf is not None and ocf is None:
            ocf = b"\x00\x00\x00\x00"
        if self.security is not None:
            data = self.security.seal(vcid, data)
        f = TmFrame(self.scid, vcid, data, self.mc_count, vc_count, fhp, ocf)
        self.mc_count = (self.mc_count + 1) & 0xFF
        self.frames += 1
        return f
