"""A radio between the OBC's COM UART and the ground station: rate, noise, bursts and slips.

``RadioChannel`` is one direction of the link: octets go in at a time (``send``), and come out
(``receive``) when the last of their bits has been on the air at ``bps`` bit/s, with what the
air did to them: bit errors at ``ber`` (hard bits) or, with ``ebn0_db``, additive white
Gaussian noise on BPSK soft symbols for that Eb/N0 per information bit (``rate``: information
bits per channel bit, e.g. 256/648 for 256-octet frames with concatenated coding), error
bursts (``burst_rate`` per bit, ``burst_length`` bits each wrong with probability 1/2) and bit
slips (``slip_rate`` per bit: a bit dropped or repeated). The clock is the caller's (a
simulated one in tests). ``busy`` counts the seconds the channel was on the air.

``RadioLink`` runs a channel each way in real time between the OBC's side (the controller end
of its UART, a pty; or, with ``space_peer``, a UDP link of the frame processor that sends its
channel octets to ``space_address``) and a ground station's ``UdpLink`` (soft symbols or
octets), and takes the station's CLTUs back on the same UDP socket: the simulation's radio,
configured from a mission's ``frames`` section (``from_mission``).
"""

import array
import math
import os
import random
import select
import socket
import threading
import time
from collections import deque


class RadioChannel:
    """One direction of the radio link (see the module)."""

    def __init__(self, bps, ber=0.0, ebn0_db=None, rate=1.0, burst_rate=0.0, burst_length=8,
                 slip_rate=0.0, seed=1, soft=None):  # fmt: skip
        if bps <= 0:
            raise ValueError("radio rate %r bit/s; expected a positive rate" % (bps,))
        self.bps = bps
        self.ber = ber
        self.ebn0_db = ebn0_db
        self.soft = ebn0_db is not None if soft is None else soft
        self.sigma = None
        if ebn0_db is not None:
            esn0 = 10 ** (ebn0_db / 10) * rate
            self.sigma = math.sqrt(1 / (2 * esn0))
        self.burst_rate = burst_rate
        self.burst_length = burst_length
        self.slip_rate = slip_rate
        self.rng = random.Random(seed)
        self._air = deque()  # (time the last bit is received, symbols)
        self._free_at = 0.0
        self._carry = []
        self.busy = 0.0
        self.bits = 0
        self.flipped = 0  # hard bit errors put in (AWGN errors are counted by the receiver)
        self.slips = 0
        self.bursts = 0

    def send(self, data, now):
        """Put ``data`` on the air at ``now`` (after what is still being sent)."""
        if not data:
            return
        start = max(now, self._free_at)
        n = len(data) * 8
        self._free_at = start + n / self.bps
        self.busy += n / self.bps
        self.bits += n
        self._air.append((self._free_at, self._impair(data)))

    def idle_at(self):
        """When the channel has sent everything it was given."""
        return self._free_at

    def receive(self, now):
        """What has arrived by ``now``: octets (hard) or a list of soft symbols."""
        out = [] if self.soft else bytearray()
        while self._air and self._air[0][0] <= now:
            out += self._air.popleft()[1]
        return out if self.soft else bytes(out)

    def _impair(self, data):
        bits = []
        for octet in data:
            for k in range(7, -1, -1):
                bits.append((octet >> k) & 1)
        rng = self.rng
        if self.slip_rate:
            bits = self._slip(bits)
        if self.burst_rate:
            i = 0
            n = len(bits)
            while i < n:
                gap = _geometric(rng, self.burst_rate)
                i += gap
                if i >= n:
                    break
                self.bursts += 1
                for j in range(i, min(n, i + self.burst_length)):
                    if rng.random() < 0.5:
                        bits[j] ^= 1
                        self.flipped += 1
                i += self.burst_length
        if self.sigma is not None:
            g = rng.gauss
            s = self.sigma
            return [(1.0 if b else -1.0) + g(0.0, s) for b in bits]
        if self.ber:
            i = _geometric(rng, self.ber)
            while i < len(bits):
                bits[i] ^= 1
                self.flipped += 1
                i += 1 + _geometric(rng, self.ber)
        if self.soft:
            return [1.0 if b else -1.0 for b in bits]
        bits = self._carry + bits  # a slip leaves a chunk a few bits off whole octets
        whole = len(bits) - len(bits) % 8
        self._carry = bits[whole:]
        return _pack(bits[:whole])

    def _slip(self, bits):
        out = []
        i = _geometric(self.rng, self.slip_rate)
        last = 0
        while i < len(bits):
            out += bits[last:i]
            self.slips += 1
            if self.rng.random() < 0.5:
                last = i + 1  # a bit lost
            else:
                out.append(bits[i])  # a bit counted twice
                last = i
            i += 1 + _geometric(self.rng, self.slip_rate)
        out += bits[last:]
        return out


def _geometric(rng, p):
    """Bits before the next event of probability ``p`` per bit."""
    if p >= 1:
        return 0
    return int(math.log(1.0 - rng.random()) / math.log(1.0 - p))


def _pack(bits):
    out = bytearray()
    for i in range(0, len(bits), 8):
        v = 0
        for b in bits[i : i + 8]:
            v = (v << 1) | b
        out.append(v)
    return bytes(out)


class RadioLink:
    """The simulation's radio in real time: the OBC's UART controller end ``uart_fd`` on one
    side, a station's UDP link at ``station`` (host, port) on the other (see the module).
    ``down`` and ``up`` are the two RadioChannels; soft symbols go as int8 (the station's
    ``udp:PORT:int8``), octets as they are."""

    def __init__(self, uart_fd, station, down, up, host="127.0.0.1", clock=time.monotonic,
                 space_peer=None, port=0):  # fmt: skip
        self.fd = uart_fd
        self.space_peer = space_peer
        self.space = None
        if uart_fd is None:  # the OBC's side on UDP
            self.space = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            self.space.bind((host, 0))
            self.space.setblocking(False)
            self.space_address = self.space.getsockname()
        else:
            os.set_blocking(uart_fd, False)
        self.station = station
        self.down = down
        self.up = up
        self.clock = clock
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind((host, port))
        self.sock.setblocking(False)
        self.address = self.sock.getsockname()
        self._stop = threading.Event()
        self._thread = None
        self.t0 = None

    @classmethod
    def from_mission(cls, link, uart_fd, station, seed=None, space_peer=None, port=0):
        """A radio for ``link`` (``obsw_host.frames.coding.LinkSettings``): its downlink and
        uplink rates (9,600 and 2,400 bit/s when the mission gives none) and radio model."""
        r = dict(link.radio)
        if seed is not None:
            r["seed"] = seed
        rate = link.frame_length / link.channel_length
        down = RadioChannel(
            link.downlink_bps or 9600, r["ber"], r["ebn0_db"], rate, r["burst_rate"],
            r["burst_length"], r["slip_rate"], r["seed"],
        )  # fmt: skip
        up = RadioChannel(link.uplink_bps or 2400, 0.0, seed=r["seed"] + 1, soft=False)
        return cls(uart_fd, station, down, up, space_peer=space_peer, port=port)

    def _space_read(self):
        if self.space is None:
            return os.read(self.fd, 65536)
        chunks = []
        while True:
            try:
                chunks.append(self.space.recv(65536))
            except OSError:
                return b"".join(chunks)

    def _space_write(self, data):
        if self.space is None:
            os.write(self.fd, data)
        elif self.space_peer is not None:
            self.space.sendto(data, self.space_peer)

    def step(self, timeout=0.01):
        now = self.clock()
        side = self.fd if self.space is None else self.space
        readable, _, _ = select.select([side, self.sock], [], [], timeout)
        if side in readable:
            try:
                self.down.send(self._space_read(), now)
            except OSError:
                pass
        if self.sock in readable:
            while True:
                try:
                    self.up.send(self.sock.recv(65536), now)
                except OSError:
                    break
        got = self.down.receive(now)
        if len(got):
            if self.down.soft:
                q = array.array("b", (max(-127, min(127, int(s * 32))) for s in got))
                data = q.tobytes()
            else:
                data = got
            for i in range(0, len(data), 8192):
                try:
                    self.sock.sendto(data[i : i + 8192], self.station)
                except OSError:
                    pass
        cltus = self.up.receive(now)
        if cltus:
            try:
                self._space_write(cltus)
            except OSError:
                pass

    def start(self):
        def run():
            while not self._stop.is_set():
                self.step()

        self._thread = threading.Thread(target=run, name="radio", daemon=True)
        self._thread.start()
        return self

    def wait(self, timeout=None):
        """Until ``stop`` (or ``timeout`` seconds)."""
        self._stop.wait(timeout)

    def stop(self):
        self._stop.set()
        if self._thread is not None:
            self._thread.join(2)
        self.sock.close()
        if self.space is not None:
            self.space.close()


def main(argv=None):
    import argparse

    from obsw_host.frames.coding import LinkSettings
    from obsw_host.mission.ids import MissionIds

    ap = argparse.ArgumentParser(
        prog="python -m obsw_sim.radio",
        description="the simulated radio between an OBC's UART and a station's UDP link, as "
        "the mission's frames section says",
    )
    ap.add_argument("--mission", required=True, help="mission folder or file")
    ap.add_argument("--uart", required=True, help="the OBC's UART device (STATE/uart_a names it)")
    ap.add_argument("--station", required=True, help="HOST:PORT of the station's UDP link")
    ap.add_argument("--port", type=int, default=0, help="this radio's UDP port (0: free)")
    ap.add_argument("--duration", type=float, help="stop after N seconds")
    args = ap.parse_args(argv)
    ids = MissionIds.locate(args.mission)
    link = LinkSettings.of(ids.config)
    host, _, port = args.station.rpartition(":")
    fd = os.open(args.uart, os.O_RDWR | os.O_NOCTTY)
    radio = RadioLink.from_mission(link, fd, (host or "127.0.0.1", int(port)), port=args.port)
    soft = "int8" if radio.down.soft else "octets"
    print("radio: %s <-> udp %s (%s), listening on udp %s:%d; down %g bit/s, up %g bit/s"
          % (args.uart, args.station, soft, radio.address[0], radio.address[1],
             radio.down.bps, radio.up.bps), flush=True)  # fmt: skip
    radio.start()
    try:
        radio.wait(args.duration)
    except KeyboardInterrupt:
        pass
    finally:
        radio.stop()
        os.close(fd)
    print("radio: %d bits down (%d flipped, %d slips), %d bits up" % (
        radio.down.bits, radio.down.flipped, radio.down.slips, radio.up.bits))  # fmt: skip
    return 0


if __name__ == "__main__":
    import sys

    sys.exit(main())
