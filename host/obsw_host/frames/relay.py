"""A ground station for Yamcs' frame link: the radio's channel coding in front of Yamcs.

Yamcs runs COP-1 and decodes TM transfer frames, but neither synchronizes nor decodes the
CCSDS channel codes. ``FrameRelay`` does that part: it reads the radio links
(``obsw_host.frames.radio``: KISS, UDP octets or soft symbols, serial), decodes the TM
(frame synchronization, Viterbi, Reed-Solomon, derandomization: ``tm_decoder``, e.g.
``LinkSettings.decoder``), drops the copies two links give of one frame, and sends each frame
to Yamcs' TM frame link on UDP (``tm_frames``), one frame per datagram; the CLTUs Yamcs sends
to ``cltu_address`` go up on every link. ``coding()`` gives the decoders' counters.
"""

import select
import socket
import time

from obsw.frames.dedup import Deduplicator

from obsw_host.frames.ground import CodedInput, coding_counters


class FrameRelay:
    """Radio links <-> Yamcs' frame link (see the module)."""

    def __init__(self, links, tm_decoder, tm_frames, host="127.0.0.1", cltu_port=0,
                 clock=time.monotonic):  # fmt: skip
        self.links = list(links)
        self.decoders = [CodedInput(tm_decoder(), getattr(link, "soft", False))
                         for link in self.links]  # fmt: skip
        self.tm_frames = tm_frames
        self.clock = clock
        self.dedup = Deduplicator(5.0)
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind((host, cltu_port))
        self.sock.setblocking(False)
        self.cltu_address = self.sock.getsockname()
        self.frames = 0  # frames sent to Yamcs
        self.cltus = 0  # CLTUs sent up

    def step(self, timeout=0.02):
        readable, _, _ = select.select(self.links + [self.sock], [], [], timeout)
        now = self.clock()
        for i, link in enumerate(self.links):
            if link not in readable:
                continue
            for frame in self.decoders[i].feed(link.read()):
                if self.dedup.duplicate(frame, i, now):
                    continue
                try:
                    self.sock.sendto(frame, self.tm_frames)
                    self.frames += 1
                except OSError:
                    pass  # Yamcs is not listening (yet): UDP drops it
        if self.sock in readable:
            while True:
                try:
                    cltu = self.sock.recv(65536)
                except OSError:
                    break
                self.cltus += 1
                for link in self.links:
                    link.write(cltu)

    def coding(self):
        return coding_counters(self.decoders)

    def run(self, stop):
        while not stop.is_set():
            self.step()

    def close(self):
        self.sock.close()
        for link in self.links:
            link.close()
