"""A CFDP entity over UDP: each PDU travels in one space packet with the mission's CFDP APID
(the spacecraft database's ``apids.cfdp``, passed in by the caller).

The entity itself is the core's sans-I/O ``CfdpEntity``; this module only moves bytes and reads
the clock.
"""

import random
import select
import socket
import time

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


class PeerError(ValueError):
    """A peer given in a form other than ID=HOST:PORT."""


class UdpEntity:
    """Moves PDUs between a CfdpEntity and a UDP socket, in space packets of APID ``apid``.

    ``loss`` drops that fraction of outgoing PDUs (for demonstrations); ``rate`` caps the
    outgoing file data in octets per second (None: as fast as the socket takes them).
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
        self.seq = 0
        self.sent = 0
        self.received = 0
        self.dropped = 0
        self.bad_packets = 0
        self._budget = 0.0
        self._last = time.monotonic()
        self.on_indication = None

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
                data = self.sock.recv(70000)
            except (BlockingIOError, InterruptedError):
                return n
            except OSError:
                return n
            try:
                pkt = SpacePacket.unpack(data)
            except SppError:
                self.bad_packets += 1
                continue
            if pkt.apid != self.apid:
                self.bad_packets += 1
                continue
            self.received += 1
            self.entity.receive(pkt.data, now)
            n += 1

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
        if self.rate is not None:
            self._budget = min(self.rate * 0.1, self._budget + (now - self._last) * self.rate)
            self._last = now
            seg = max(1, max((r.max_segment for r in ent.mib.remotes.values()), default=1024))
            limit = max(0, int(self._budget // seg))
        out = ent.transmit(now, limit)
        for dest, pdu in out:
            if self.rate is not None and pdu[0] & 0x10:
                self._budget -= len(pdu)
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
        )
        for eid in peers
    ]
    if state is not None:
        from obsw_host.cfdp.filestore import RootedFilestore

        state = RootedFilestore(state)
    return CfdpEntity(Mib(local_id, remotes), filestore, persist=persist, state=state)


def packet_type_for(onboard):
    return TYPE_TM if onboard else TYPE_TC
