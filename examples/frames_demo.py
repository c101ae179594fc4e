"""Demo: ground and spacecraft talking through the frame processor over two pseudo-UARTs, with
every TC frame signed (SDLS, HMAC-SHA-256) by keys made for the run in a temporary folder."""

import os
import select
import socket
import struct
import sys
import tempfile
import threading
import time

from obsw.frames import fop as F
from obsw.frames.cltu import encode
from obsw.frames.farm import STATE_NAMES
from obsw.frames.sdls import OUTCOME_NAMES
from obsw.frames.tc import TcFrame
from obsw.pus import sdb as sdb_module
from obsw.pus.tm import PusTm
from obsw_host.frames import keys
from obsw_host.frames.ground import Ground
from obsw_host.frames.links import FdLink, SerialLink, open_pty_pair
from obsw_host.frames.processor import FrameProcessorHost, sdb_events
from obsw_host.mission.ids import MissionIds
from obsw_host.net import DEFAULT_HOST
from obsw_host.sample import SDB_PATH

SCID = MissionIds.sample().scid  # the sample spacecraft's
APID = 0x21
TM_APID = 0x21
FRAME_LENGTH = 128


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
    with tempfile.TemporaryDirectory() as folder:
        return _run(out, timeout, os.path.join(folder, "tc.keys"))


def _run(out, timeout, key_file):
    keys.generate(key_file)
    onboard_security, _ = keys.load(key_file, key_file + ".onboard")
    ground_security, _ = keys.load(key_file, key_file + ".ground")
    event_apid, event_ids = sdb_events(sdb_module.load(SDB_PATH))
    ctrl_a, dev_a = open_pty_pair()
    ctrl_b, dev_b = open_pty_pair()
    app = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    app.bind((DEFAULT_HOST, 0))
    app_port = app.getsockname()[1]
    obc = FrameProcessorHost(
        SerialLink(dev_a), SerialLink(dev_b), SCID, tm_port=0,
        routes={APID: (DEFAULT_HOST, app_port)},
        tm_frame_length=FRAME_LENGTH, clcw_period=0.5, security=onboard_security,
        event_apid=event_apid, event_ids=event_ids,
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
        corrupt=corrupt, security=ground_security,
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
                app.sendto(reply, (DEFAULT_HOST, obc.tm_port))
                out("  app sent TM packet %s" % reply.hex())
            if until():
                return True
        return False

    try:
        out("obsw frames demo: ground <-> 2 pseudo-UARTs <-> frame processor <-> UDP app")
        sa = ground_security.sa_for(0, ground.map_id)
        out("  TC security: SA %d on VC 0, HMAC-SHA-256 MAC of %d octets, keys in a temp file" % (
            sa.spi, sa.mac_length))  # fmt: skip
        out("  links: A=%s B=%s, TC to APID %d on UDP %d, TM from UDP %d" % (
            dev_a, dev_b, APID, app_port, obc.tm_port))  # fmt: skip
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
            out("ground: TC packet %s in signed AD frame N(S)=%d SN=%d (%d bytes) in a CLTU" % (
                pkt.hex(), frame.seq, sa.sn_sent, len(frame.pack())))  # fmt: skip
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
        ok &= _forgery(out, ground, obc, pump, event_apid, event_ids)
        c = obc.core.counters
        out("frame processor: %d CLTUs, %d bit(s) corrected, %d duplicate(s) dropped, "
            "%d frame(s) accepted, %d rejected, %d packet(s) routed, %d TM frames" % (
                c["cltus"], c["corrected_bits"], c["duplicates"], c["accepted"],
                c["tc_rejected"], c["packets_routed"], c["tm_frames"]))  # fmt: skip
        ok &= c["corrected_bits"] >= 1 and c["duplicates"] >= 1 and c["packets_routed"] == 2
        ok &= c["tc_rejected"] == 1
        ok &= sum(1 for p in ground.packets if p[:2] != bytes((0x08, event_apid))) == 2
        out("result: %s" % ("every TC delivered once, every TM received" if ok else "FAILED"))
    finally:
        stop.set()
        worker.join(2)
        obc.close()
        for link in ground.links:
            link.close()
        app.close()
    return 0 if ok else 1


def _forgery(out, ground, obc, pump, event_apid, event_ids):
    """A forged copy of the last signed frame, sent on link A: rejected, and reported."""
    good = ground.sent_frames[-1].pack()
    data = bytearray(TcFrame.unpack(good).data)
    data[-20] ^= 0x01  # an octet of the packet; the FECF of the re-made frame is good
    ground.links[0].enabled = True
    ground.links[0].write(encode(TcFrame(ground.scid, 0, bytes(data), 0, True).pack()))
    out("attacker: the last frame with one bit changed (FECF good), as a BD frame on link A")
    names = dict((event_ids[i], OUTCOME_NAMES[i]) for i in range(1, len(event_ids)))

    def reported():
        return [p for p in ground.packets if ((p[0] & 7) << 8) | p[1] == event_apid]

    if not pump(lambda: reported()):
        return False
    tm = PusTm.unpack(reported()[0])
    event = (tm.data[0] << 8) | tm.data[1]
    vcid, spi, sn = struct.unpack(">BHQ", tm.data[2:])
    out("ground: TM[5,%d] event 0x%04X (TC frame rejected: %s) VC %d SPI %d" % (
        tm.subtype, event, names.get(event, "?"), vcid, spi))  # fmt: skip
    return names.get(event) == "bad_mac"


if __name__ == "__main__":
    sys.exit(run())
