"""A CFDP entity over UDP: each PDU travels in one space packet with the mission's CFDP APID
(the spacecraft database's ``apids.cfdp``, passed in by the caller).

The entity itself is the core's sans-I/O ``CfdpEntity``; this module only moves bytes and reads
the clock.
"""

import random
import select
import socket
import time

from obsw.cfdp.defs import DIR_NAK
from obsw.cfdp.entity import CfdpEntity
from obsw.cfdp.mib import Mib, RemoteEntity
from obsw.spp import TYPE_TC, TYPE_TM, SpacePacket, SppError

from obsw_host.net import DEFAULT_HOST


def parse_peer(text):
    """'2=127.0.0.1:5101' -> (2, ('127.0.0.1', 5101)); PeerError if it is not that form."""
    eid, sep, addr = text.partition("=")
    host, _, port = addr.rpartition(":")
    try:
        if not sep:
            raise ValueError
        eid, port = int(eid, 0), int(port)
        if not (0 <= eid and 0 < port < 65536):
            raise ValueError
    except ValueError:
        raise PeerError(
            "--peer %r: expected ID=HOST:PORT, such as 2=127.0.0.1:5100" % text
        ) from None
    return eid, (host or DEFAULT_HOST, port)


PACE_START = 16e6  # octets/s of file data a paced sender starts at
PACE_MIN = 64e3
PACE_MAX = 1e9
PACE_STEP = 0.25  # seconds between increases; and between two halvings
PACE_RUN = 8  # segments in a row asked again: the receiver overflowed, not the link
_RECV = 70000  # octets: more than the largest space packet a UDP datagram brings


class PeerError(ValueError):
    """A peer given in a form other than ID=HOST:PORT."""


class UdpEntity:
    """Moves PDUs between a CfdpEntity and a UDP socket, in space packets of APID ``apid``.

    ``loss`` drops that fraction of outgoing PDUs (for demonstrations); ``rate`` caps the
    outgoing file data in octets per second (None: paced by the link, see below).

    Pacing against the link (``pace``, on unless ``rate`` is given): UDP has no flow control,
    and a sender that outruns its receiver loses whole runs of datagrams in the receiver's
    socket buffer, which come back as NAKs for long ranges, which are sent again as fast, and
    so on (a retransmission storm). Random loss on a link loses single segments; a NAK that
    asks for a run of ``PACE_RUN`` segments or more is the receiver overflowing. Then the
    file data rate is halved (not below ``PACE_MIN``), and it grows again by a tenth every
    ``PACE_STEP`` seconds without such a NAK (additive increase, multiplicative decrease).
    """

    def __init__(
        self,
        entity,
        bind,
        peers,
        *,
        apid,
        packet_type=TYPE_TM,
        loss=0.0,
        seed=1,
        rate=None,
        drop=None,
        pace=None,
    ):
        self.entity = entity
        self.peers = dict(peers)
        self.apid = apid
        self.packet_type = packet_type
        self.loss = loss
        self.rng = random.Random(seed)
        self.rate = rate
        self.drop = drop  # optional callable(pdu) -> bool, for demonstrations
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
        self.sock.bind(bind)
        self.address = self.sock.getsockname()
        # datagrams are received into this buffer and copied at their size: a fresh 70,000
        # octet buffer per datagram, shrunk to what came, fragmented the heap
        self._buf = bytearray(_RECV)
        self._view = memoryview(self._buf)
        self.seq = 0
        self.sent = 0
        self.received = 0
        self.dropped = 0
        self.bad_packets = 0
        self._budget = 0.0
        self._last = time.monotonic()
        self.on_indication = None
        self.pace = rate is None if pace is None else pace
        self.rate_changes = 0
        self._runs = set()  # starts of the runs already slowed down for
        if self.pace:
            self.rate = PACE_START
        self._grow_at = self._last + PACE_STEP

    def close(self):
        self.sock.close()

    def _send(self, dest, pdu):
        addr = self.peers.get(dest)
        if addr is None:
            return
        if (self.drop is not None and self.drop(pdu)) or (
            self.loss and self.rng.random() < self.loss
        ):
            self.dropped += 1
            return
        pkt = SpacePacket(self.packet_type, self.apid, pdu, seq_count=self.seq).pack()
        self.seq = (self.seq + 1) & 0x3FFF
        try:
            self.sock.sendto(pkt, addr)
            self.sent += 1
        except OSError:
            self.dropped += 1

    def _receive_all(self, now):
        n = 0
        while True:
            try:
                size = self.sock.recv_into(self._buf)
            except (BlockingIOError, InterruptedError):
                return n
            except OSError:
                return n
            data = bytes(self._view[:size])
            try:
                pkt = SpacePacket.unpack(data)
            except SppError:
                self.bad_packets += 1
                continue
            if pkt.apid != self.apid:
                self.bad_packets += 1
                continue
            self.received += 1
            pdu = self.entity.receive(pkt.data, now)
            if self.pace and pdu is not None and getattr(pdu, "CODE", None) == DIR_NAK:
                self._paced_by(pdu, now)
            n += 1

    def _paced_by(self, nak, now):
        seg = max(1, max((r.max_segment for r in self.entity.mib.remotes.values()), default=1))
        # a run asked for again (the NAK timer repeats what is still missing) is no news
        runs = [s for s, e in nak.segments if e - s >= PACE_RUN * seg and s not in self._runs]
        if runs:
            if len(self._runs) > 4096:
                self._runs.clear()
            self._runs.update(runs)
            if now >= self._slow_until:  # one halving per round trip of NAKs
                actual = self._measure(now)  # what it really sent, unless it mostly paused
                basis = actual if self.rate / 4 <= actual < self.rate else self.rate
                self.rate = max(PACE_MIN, basis / 2)
                self._budget = min(self._budget, 0.0)
                self._slow_until = now + PACE_STEP
                self.rate_changes += 1
            self._grow_at = now + PACE_STEP

    _slow_until = 0.0

    def _measure(self, now):
        """The file data rate actually sent since the last look (octets/s)."""
        dt = now - self._window_start
        if dt >= PACE_STEP / 2:
            self._actual = self._window_bytes / dt
            self._window_bytes = 0
            self._window_start = now
        return self._actual

    _actual = PACE_START
    _window_bytes = 0
    _window_start = 0.0

    def _grow(self, now):
        if self.pace and now >= self._grow_at:
            # only a rate the sender reaches grows (one it cannot reach says nothing)
            if self._measure(now) >= 0.8 * self.rate:
                self.rate = min(PACE_MAX, self.rate * 1.1)
            self._grow_at = now + PACE_STEP

    def step(self, max_wait=0.05):
        """Wait for traffic or the next deadline (at most ``max_wait`` s), then do all work."""
        ent = self.entity
        now = time.monotonic()
        wait = max_wait
        if ent.pending() and (self.rate is None or self._budget > 0):
            wait = 0
        else:
            d = ent.next_deadline()
            if d is not None:
                wait = max(0.0, min(wait, d - now))
        r, _, _ = select.select([self.sock], [], [], wait)
        now = time.monotonic()
        if r:
            self.sock.setblocking(False)
            self._receive_all(now)
            self.sock.setblocking(True)
        ent.poll(now)
        limit = 64
        self._grow(now)
        if self.rate is not None:
            seg = max(1, max((r.max_segment for r in ent.mib.remotes.values()), default=1024))
            # a tenth of a second's worth, and never less than two segments: a slow rate sends,
            # and the credit that grows while a segment's worth waits for a late step is kept
            cap = max(self.rate * 0.1, 2 * seg)
            self._budget = min(cap, self._budget + (now - self._last) * self.rate)
            self._last = now
            limit = max(0, int(self._budget // seg))
        out = ent.transmit(now, limit)
        for dest, pdu in out:
            if self.rate is not None and pdu[0] & 0x10:
                self._budget -= len(pdu)
                self._window_bytes += len(pdu)
            self._send(dest, pdu)
        inds = ent.pop_indications()
        if self.on_indication is not None:
            for i in inds:
                self.on_indication(i)
        return inds

    def run_until(self, done, timeout=None):
        """Step until ``done()`` is true; False if ``timeout`` seconds passed first."""
        end = None if timeout is None else time.monotonic() + timeout
        while not done():
            if end is not None and time.monotonic() > end:
                return False
            self.step()
        return True


MAX_GAPS = 1 << 16  # missing ranges a host receiver tracks (a few MB; the MIB's default is
# a board's): a 50 MB file at 10 % loss has about 5,000, and merging gaps re-asks for data


def make_entity(
    local_id,
    peers,
    filestore,
    *,
    mode=0,
    segment=1024,
    persist=True,
    ack_interval=1.0,
    nak_interval=1.0,
    limit=10,
    inactivity=60.0,
    keep_alive=0.5,
    state=None,
    max_gaps=MAX_GAPS,
):
    """A CfdpEntity with one MIB entry per peer and timer values suited to a UDP link (a
    receiver reports its progress in a keep-alive PDU every ``keep_alive`` seconds).
    ``state``: the folder of the persisted state, outside the filestore (None: inside it)."""
    remotes = [
        RemoteEntity(
            eid,
            mode=mode,
            max_segment=segment,
            ack_interval=ack_interval,
            ack_limit=limit,
            nak_interval=nak_interval,
            nak_limit=limit,
            inactivity=inactivity,
            check_interval=ack_interval,
            keep_alive_interval=keep_alive,
            max_gaps=max_gaps,
        )
        for eid in peers
    ]
    if state is not None:
        from obsw_host.cfdp.filestore import RootedFilestore

        state = RootedFilestore(state)
    return CfdpEntity(Mib(local_id, remotes), filestore, persist=persist, state=state)


def packet_type_for(onboard):
    return TYPE_TM if onboard else TYPE_TC
