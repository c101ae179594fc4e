"""A ground station for a mission control process: space packets on UDP, frames on the links.

TC packets that arrive on the station's UDP socket go up through FOP-1 (AD service, MAP
``map_id``) as CLTUs on every link; TM frames read from the links are decoded and their
packets go, unchanged, to the mission control process (``mcs``, or whoever sent the last TC)
on UDP; ``routes`` (APID -> UDP address) sends the packets of those APIDs elsewhere (a ground
CFDP entity, say), whose TC packets then go up without taking the mission control process's
place, and after its TCs: one goes to COP-1 only when no TC waits there, so an operator's TC
waits at most for FOP-1's window, never behind a file's PDUs. ``downlinked`` keeps (VC ID,
packet) of the packets forwarded, so a test or the demo can tell real-time telemetry from
playback.

``GroundStation.for_mission(ids, links)`` configures it from a mission (SCID, TC VC and MAP,
TM frame length and coding); the links may be any of ``obsw_host.frames.radio`` (KISS over a
serial port or TCP, UDP bits or soft symbols) or a serial link (``links``).
"""

import socket
import time
from collections import deque

from obsw.frames import fop as F
from obsw.frames.errors import FrameError

from obsw_host.frames.ground import Ground
from obsw_host.net import DEFAULT_HOST


class GroundStation:
    """``Ground`` (FOP-1, CLTUs, TM decoding) between ``links`` and one UDP socket."""

    def __init__(
        self,
        links,
        scid,
        host=DEFAULT_HOST,
        port=0,
        mcs=None,
        keep=10000,
        clock=None,
        routes=None,
        **options,
    ):
        self.ground = Ground(links, scid, **options)
        self.routes = dict(routes or {})
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind((host, port))
        self.sock.setblocking(False)
        self.address = self.sock.getsockname()
        self.mcs = mcs
        self.downlinked = deque((), keep)
        self.clock = clock or time.monotonic
        self._t0 = self.clock()
        self.uplinked = 0
        self.refused = 0  # packets that could not go up (too long, or no operational SA)
        self.routed = deque()  # TC packets from the routes, waiting for COP-1 to be free
        self._initiated = False

    @classmethod
    def for_mission(cls, ids, links, **options):
        """A station for mission ``ids`` (``MissionIds``) on ``links``: its SCID, TC VC and
        packets MAP, TM frame length and channel coding (``frames`` section)."""
        from obsw_host.frames.coding import LinkSettings

        link = LinkSettings.of(ids.config)
        options.setdefault("vcid", ids.tc_vc)
        options.setdefault("map_id", ids.maps["packets"])
        options.setdefault("tm_frame_length", link.frame_length)
        options.setdefault("tm_decoder", link.decoder)
        return cls(links, ids.scid, **options)

    def coding(self):
        """The channel decoders' counters (``Ground.coding``)."""
        return self.ground.coding()

    def now(self):
        return self.clock() - self._t0

    def step(self, timeout=0.02):
        """Forward what came from the mission control process and from the links."""
        now = self.now()
        if not self._initiated:
            self.ground.initiate(now)  # AD service with Unlock; TCs queue until it is active
            self._initiated = True
        while True:
            try:
                packet, sender = self.sock.recvfrom(65542)
            except OSError:
                break
            if sender in self.routes.values():
                self.routed.append(packet)
                continue
            if self.mcs != sender:
                self.mcs = sender
            self._up(packet, now)
        while self.routed and not self.ground.queue:
            self._up(self.routed.popleft(), now)
        self.ground.poll(now, timeout)
        ch = self.ground.channel_packets
        while ch:
            vcid, packet = ch.popleft()
            self.downlinked.append((vcid, packet))
            to = self.mcs
            if self.routes and len(packet) >= 2:
                to = self.routes.get((packet[0] & 7) << 8 | packet[1], to)
            if to is not None:
                try:
                    self.sock.sendto(packet, to)
                except OSError:
                    pass  # the mission control process is gone: UDP drops it
        self.ground.packets.clear()  # kept in ``downlinked`` with their VC
        if self.ground.fop.state == F.INITIAL and self.ground.fop.outstanding == 0:
            self._initiated = False  # FOP-1 gave up (e.g. links cut): start it again

    def _up(self, packet, now):
        try:
            self.ground.send(packet, now)
        except FrameError:
            self.refused += 1
            return
        self.uplinked += 1

    def run(self, stop):
        """Step until ``stop`` (a threading.Event) is set."""
        while not stop.is_set():
            self.step()

    def close(self):
        self.sock.close()
        for link in self.ground.links:
            link.close()
