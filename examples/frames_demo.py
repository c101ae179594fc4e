"""Demo: ground and spacecraft talking through the frame processor over two pseudo-UARTs."""

import select
import socket
import sys
import threading
import time

from obsw.frames import fop as F
from obsw.frames.farm import STATE_NAMES
from obsw_host.frames.ground import Ground
from obsw_host.frames.links import FdLink, SerialLink, open_pty_pair
from obsw_host.frames.processor import FrameProcessorHost

SCID = 0x2A
APID = 0x21
TM_APID = 0x21
FRAME_LENGTH = 128


def _free_port_base(apid):
    # Find a UDP port the application can bind so that port = base + APID holds.
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port - apid, port


def _tc_packet(seq, payload):
    n = len(payload)
    return bytes((0x18 | APID >> 8, APID & 0xFF, 0xC0 | seq >> 8, seq & 0xFF, 0, n - 1)) + payload


def _tm_packet(seq, payload):
    n = len(payload)
    return (
        bytes((0x08 | TM_APID >> 8, TM_APID & 0xFF, 0xC0 | seq >> 8, seq & 0xFF, 0, n - 1))
        + payload
    )


def run(out=print, timeout=5.0):
    """Run the demo; returns 0 when every step worked (1 otherwise)."""
    ctrl_a, dev_a = open_pty_pair()
    ctrl_b, dev_b = open_pty_pair()
    base, app_port = _free_port_base(APID)
    app = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    app.bind(("127.0.0.1", app_port))
    obc = FrameProcessorHost(
        SerialLink(dev_a), SerialLink(dev_b), SCID, port_base=base, tm_port=0,
        tm_frame_length=FRAME_LENGTH, clcw_period=0.5,
    )  # fmt: skip
    stop = threading.Event()
    worker = threading.Thread(target=obc.run, args=(stop,), daemon=True)
    worker.start()
    flips = []

    def corrupt(link, cltu):
        if link == 0 and not flips:
            flips.append(link)
            damaged = bytearray(cltu)
            damaged[2] ^= 0x10  # one bit of the first codeblock, link A only
            return bytes(damaged)
        return cltu

    ground = Ground(
        [FdLink(ctrl_a, "A"), FdLink(ctrl_b, "B")], SCID, tm_frame_length=FRAME_LENGTH,
        corrupt=corrupt,
    )  # fmt: skip
    ok = True
    t0 = time.monotonic()

    def now():
        return time.monotonic() - t0

    def pump(until, limit=timeout):
        end = now() + limit
        while now() < end:
            ground.poll(now(), 0.02)
            r, _, _ = select.select([app], [], [], 0)
            if r:
                pkt, _ = app.recvfrom(65536)
                out("  app (UDP %d) got TC packet %s" % (app_port, pkt.hex()))
                reply = _tm_packet(len(pkt), b"ACK " + pkt[6:])
                app.sendto(reply, ("127.0.0.1", obc.tm_port))
                out("  app sent TM packet %s" % reply.hex())
            if until():
                return True
        return False

    try:
        out("obsw frames demo: ground <-> 2 pseudo-UARTs <-> frame processor <-> UDP app")
        out("  links: A=%s B=%s, TC to UDP port %d+APID, TM from UDP %d" % (
            dev_a, dev_b, base, obc.tm_port))  # fmt: skip
        ground.initiate(now())
        out("ground: Initiate AD with Unlock (BC frame %s)" % ground.sent_frames[-1].pack().hex())
        ok &= pump(lambda: ground.fop.state == F.ACTIVE)
        out("  FOP-1 %s after CLCW %r" % (F.STATE_NAMES[ground.fop.state], ground.demux.clcw))
        for step, cut in ((1, False), (2, True)):
            if cut:
                ground.links[1].enabled = False
                obc.links[1].enabled = False
                out("link B cut")
            pkt = _tc_packet(step, b"PING %d" % step)
            ground.send(pkt, now())
            frame = ground.sent_frames[-1]
            out("ground: TC packet %s in AD frame N(S)=%d (%d bytes) in a CLTU" % (
                pkt.hex(), frame.seq, len(frame.pack())))  # fmt: skip
            if step == 1:
                out("  link A: one bit flipped in the first codeblock; link B: clean")
            before = len(ground.packets)
            ok &= pump(lambda b=before: len(ground.packets) > b and ground.idle)
            for tm in list(ground.packets)[before:]:
                out("ground: TM packet %s" % tm.hex())
            farm = obc.core.farms[0]
            out(
                "  CLCW %r; FARM %s V(R)=%d"
                % (ground.demux.clcw, STATE_NAMES[farm.state], farm.vr)
            )
        c = obc.core.counters
        out("frame processor: %d CLTUs, %d bit(s) corrected, %d duplicate(s) dropped, "
            "%d frame(s) accepted, %d packet(s) routed, %d TM frames" % (
                c["cltus"], c["corrected_bits"], c["duplicates"], c["accepted"],
                c["packets_routed"], c["tm_frames"]))  # fmt: skip
        ok &= c["corrected_bits"] >= 1 and c["duplicates"] >= 1 and c["packets_routed"] == 2
        ok &= len(ground.packets) == 2
        out("result: %s" % ("every TC delivered once, every TM received" if ok else "FAILED"))
    finally:
        stop.set()
        worker.join(2)
        obc.close()
        for link in ground.links:
            link.close()
        app.close()
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(run())
