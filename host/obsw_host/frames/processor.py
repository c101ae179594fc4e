"""The frame processor process: two serial links to the COM module, UDP to the applications.

Telecommand packets go to UDP port ``port_base + APID`` (5000 + APID by default), sent from
the ``tm_port`` socket, so an application answering the sender reaches the TM input; telemetry
packets sent to ``tm_port`` (4999) leave as TM frames on both links, on the VC of their APID
(the real-time VC unless mapped). Each entry of ``vc_ports`` (VC ID -> UDP port) is one more
input whose packets all go on that VC, unchanged: by default the playback VC of the plan on
``tm_port + 1`` (5000 would collide with APID 0), where the PUS application process sends
what service 15 retrieves from its packet stores.
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
        vc_ports=None,
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
        self.core = FrameProcessor(scid, self._route, self._essential, **options)
        if vc_ports is None:
            pb = self.core.playback_vcid
            vc_ports = {} if pb is None else {pb: tm_port + 1 if tm_port else 0}
        self.tm = self._bind(tm_port)
        self.out = self.tm
        self.tm_port = self.tm.getsockname()[1]
        self.vc_inputs = {}  # socket -> VC ID
        self.vc_ports = {}  # VC ID -> bound UDP port
        try:
            for vcid, port in vc_ports.items():
                try:
                    self.core.mux.channel(vcid)
                except KeyError:
                    raise ValueError(
                        "no TM virtual channel %r for UDP port %d" % (vcid, port)
                    ) from None
                s = self._bind(port)
                self.vc_inputs[s] = vcid
                self.vc_ports[vcid] = s.getsockname()[1]
        except (OSError, ValueError):
            self.close()
            raise

    @property
    def playback_port(self):
        """The UDP port whose packets go on the playback VC (None without one)."""
        return self.vc_ports.get(self.core.playback_vcid)

    def _bind(self, port):
        s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        s.bind((self.host, port))
        s.setblocking(False)
        return s

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
        inputs = self.links + [self.tm] + list(self.vc_inputs)
        readable, _, _ = select.select(inputs, [], [], timeout)
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
                except OSError:  # nothing more (or an ICMP error from a TC sent earlier)
                    break
                self.core.send_packet(packet)
        for s, vcid in self.vc_inputs.items():
            if s in readable:
                while True:
                    try:
                        packet = s.recv(65542)
                    except OSError:
                        break
                    self.core.send_packet(packet, vcid)
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
        self.tm.close()
        for s in self.vc_inputs:
            s.close()
