"""The frame processor process: two serial links to the COM module, UDP to the applications.

Telecommand packets go to UDP port ``port_base + APID`` (5000 + APID by default); telemetry
packets sent by the applications to ``tm_port`` leave as TM frames on both links.
"""

import select
import socket
import time

from obsw.frames.processor import FrameProcessor

from obsw_host.frames.links import SerialLink

DEFAULT_TM_PORT = 4999


class FrameProcessorHost:
    """Runs the core FrameProcessor on two links (SerialLink-like objects or device paths)."""

    def __init__(
        self,
        link_a,
        link_b,
        scid,
        host="127.0.0.1",
        port_base=5000,
        tm_port=DEFAULT_TM_PORT,
        essential_port=None,
        clock=time.monotonic,
        **options,
    ):
        self.links = [
            SerialLink(link) if isinstance(link, str) else link for link in (link_a, link_b)
        ]
        self.host = host
        self.port_base = port_base
        self.essential_port = essential_port
        self.clock = clock
        self.essential = []
        self.out = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.tm = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.tm.bind((host, tm_port))
        self.tm.setblocking(False)
        self.tm_port = self.tm.getsockname()[1]
        self.core = FrameProcessor(scid, self._route, self._essential, **options)

    def _route(self, apid, packet):
        try:
            self.out.sendto(packet, (self.host, self.port_base + apid))
        except OSError:
            pass  # nobody listening: UDP drops it, as the thesis' processes expect

    def _essential(self, unit):
        self.essential.append(unit)
        if self.essential_port is not None:
            self.out.sendto(unit, (self.host, self.essential_port))

    def step(self, timeout=0.05):
        """Wait up to ``timeout`` for input, process it, write due telemetry to both links."""
        readable, _, _ = select.select(self.links + [self.tm], [], [], timeout)
        now = self.clock()
        for i, link in enumerate(self.links):
            if link in readable:
                data = link.read()
                if data and link.enabled:
                    self.core.receive(i, data, now)
        if self.tm in readable:
            while True:
                try:
                    packet = self.tm.recv(65542)
                except BlockingIOError:
                    break
                self.core.send_packet(packet)
        for cadu in self.core.tm_output(now):
            for link in self.links:
                link.write(cadu)

    def run(self, stop=None, duration=None):
        end = None if duration is None else self.clock() + duration
        while not (stop is not None and stop.is_set()) and (end is None or self.clock() < end):
            self.step()

    def close(self):
        for link in self.links:
            link.close()
        self.out.close()
        self.tm.close()
