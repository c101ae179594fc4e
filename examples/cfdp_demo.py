"""The CFDP part of `obsw demo`: an onboard and a ground entity on loopback UDP; a class 2 put
over a link that drops PDUs (NAKs and retransmissions shown), then a get by proxy put."""

import os
import sys
import tempfile
import time

from obsw.cfdp import msgs
from obsw.cfdp.defs import CONDITION_NAMES, DIR_NAK
from obsw_host.cfdp.filestore import RootedFilestore
from obsw_host.cfdp.link import UdpEntity, make_entity, packet_type_for
from obsw_host.sample import load_sdb

GROUND = 1
ONBOARD = 2


def _directive(pdu):
    if pdu[0] & 0x10:
        return None
    return pdu[4 + 2 * (((pdu[3] >> 4) & 7) + 1) + (pdu[3] & 7) + 1]


def run(out=print, size=200000, loss=0.05, seed=7, timeout=20.0):
    """Run the demo; returns True when both transfers delivered identical files. Its files
    live in a temporary folder removed at the end, also when interrupted."""
    with tempfile.TemporaryDirectory(prefix="obsw-cfdp-demo-") as work:
        return _run(work, out, size, loss, seed, timeout)


def _run(work, out, size, loss, seed, timeout):
    gfs = RootedFilestore(os.path.join(work, "ground"))
    ofs = RootedFilestore(os.path.join(work, "onboard"))
    payload = os.urandom(size)
    gfs.write_bytes("patch.bin", payload)
    ofs.write_bytes("science.dat", payload[::-1])
    ground = make_entity(
        GROUND, [ONBOARD], gfs, segment=512, ack_interval=0.3, nak_interval=0.3, persist=False
    )
    onboard = make_entity(
        ONBOARD, [GROUND], ofs, segment=512, ack_interval=0.3, nak_interval=0.3, persist=False
    )
    apid = load_sdb().apid("cfdp")  # the sample spacecraft's CFDP APID
    g = UdpEntity(
        ground, ("127.0.0.1", 0), {}, apid=apid, packet_type=packet_type_for(False), loss=loss,
        seed=seed,
    )  # fmt: skip
    o = UdpEntity(
        onboard, ("127.0.0.1", 0), {}, apid=apid, packet_type=packet_type_for(True), loss=loss,
        seed=seed + 1,
    )  # fmt: skip
    g.peers[ONBOARD] = o.address
    o.peers[GROUND] = g.address
    shown = {"nak": 0}

    def show(side):
        def on(ind):
            i = ind.info
            if ind.kind == "finished":
                out(
                    "  %s: transaction %d:%d finished (%s) as %s"
                    % (
                        side,
                        ind.tid[0],
                        ind.tid[1],
                        CONDITION_NAMES.get(i["condition"]),
                        "sender" if i["role"] == "S" else "receiver",
                    )
                )
            elif ind.kind == "metadata" and i.get("dest_name"):
                out("  %s: receiving %s (%d octets)" % (side, i["dest_name"], i["size"]))

        return on

    g.on_indication = show("ground")
    o.on_indication = show("onboard")
    orig = o._send

    def spy(dest, pdu):
        if _directive(pdu) == DIR_NAK and shown["nak"] < 3:
            shown["nak"] += 1
            out("  onboard: NAK for missing segments (%d octets)" % len(pdu))
        orig(dest, pdu)

    o._send = spy

    def both(done):
        end = time.monotonic() + timeout
        while not done() and time.monotonic() < end:
            g.step(0.01)
            o.step(0.01)
        return done()

    ok = True
    try:
        out(
            "CFDP: ground entity %d and onboard entity %d on loopback UDP, %d%% of PDUs "
            "dropped" % (GROUND, ONBOARD, int(loss * 100))
        )
        out("uplink: class 2 put of patch.bin (%d octets)" % size)
        t0 = time.monotonic()
        tid = ground.put(ONBOARD, "patch.bin", "patch.bin", now=t0)
        both(lambda: not ground.tx and not onboard.tx)
        same = ofs.exists("patch.bin") and ofs.read_bytes("patch.bin") == payload
        ok &= same
        st = ground.stats
        out(
            "  %s in %.2f s: %d PDUs dropped by the link, %d file data PDUs retransmitted"
            % (
                "delivered intact" if same else "FAILED",
                time.monotonic() - t0,
                g.dropped + o.dropped,
                st["retransmitted_pdus"],
            )
        )
        out("downlink: get of science.dat by proxy put (ground asks, onboard sends)")
        t0 = time.monotonic()
        req = ground.put(
            ONBOARD,
            messages=[msgs.proxy_put_request(GROUND, "science.dat", "science.dat")],
            now=t0,
        )
        both(
            lambda: (
                ground.tx == {}
                and onboard.tx == {}
                and gfs.exists("science.dat")
                and time.monotonic() - t0 > 0.05
            )
        )
        same = gfs.exists("science.dat") and gfs.read_bytes("science.dat") == payload[::-1]
        ok &= same
        out(
            "  %s in %.2f s (request %d:%d, %d retransmissions onboard)"
            % (
                "delivered intact" if same else "FAILED",
                time.monotonic() - t0,
                req[0],
                req[1],
                onboard.stats["retransmitted_pdus"],
            )
        )
        del tid
    finally:
        g.close()
        o.close()
    return ok


if __name__ == "__main__":
    sys.exit(0 if run() else 1)
