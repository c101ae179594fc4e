"""Demo: the space link as a radio makes it. The sample spacecraft downlinks TM with
concatenated coding (Reed-Solomon (255,223) interleaved 2, then the rate 1/2 convolutional
code) at 9,600 bit/s through a radio model that flips one bit in a thousand; the ground's
frame relay synchronizes, Viterbi- and RS-decodes and hands Yamcs plain frames; Yamcs' COP-1
commands go up at 2,400 bit/s. The operator sees housekeeping, a completed ping, the corrected
symbols and no lost frame. Then the same link simulated on a clock: housekeeping keeps its
period while a playback dump and a CFDP downlink share the rest. Skipped, saying why, when
Java or Yamcs is not installed (the simulated part still runs)."""

import logging
import os
import socket
import tempfile
import threading

from obsw_host.frames.coding import LinkSettings
from obsw_host.sample import SDB_PATH

MISSION = "/obsw-demo"
SETTINGS = {
    "tm_frame_length": 256,
    "tm_coding": {"scheme": "concatenated", "rs_e": 16, "interleave": 2},
    "downlink_bps": 9600,
    "uplink_bps": 2400,
    "radio": {"ber": 1e-3, "seed": 7},
}


def _free_port(kind=socket.SOCK_STREAM):
    s = socket.socket(socket.AF_INET, kind)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def run(out=print):
    link = LinkSettings(SETTINGS)
    out("link: %s, uplink %g bit/s, radio BER %g" % (
        link.describe(), link.uplink_bps, link.radio["ber"]))  # fmt: skip
    _yamcs(out, link)
    _simulated(out)
    return 0


def _yamcs(out, link):
    from obsw_host.yamcs import database, server
    from obsw_host.yamcs.instance import write_instance

    problem = server.missing()
    if problem is None:
        try:
            from yamcs.client import YamcsClient
        except ImportError:
            problem = "the Yamcs client is not installed: pip install yamcs-client"
    if problem:
        out("Yamcs part skipped: " + problem)
        return
    from obsw_sim.spacelink import YamcsSpaceLink

    with tempfile.TemporaryDirectory() as folder:
        tm_frames = _free_port(socket.SOCK_DGRAM)
        space = YamcsSpaceLink(SDB_PATH, os.path.join(folder, "sat"), link, tm_frames)
        http = _free_port()
        quiet = [logging.getLogger(n) for n in ("yamcs-client", "websocket")]
        levels = [q.level for q in quiet]
        try:
            write_instance(folder, database.load(SDB_PATH), "frames",
                           dict(space.ports(), tm_frames=tm_frames), http)  # fmt: skip
            space.start()
            yamcs = server.Yamcs(folder, http).start(timeout=120)
            try:
                _operate(out, YamcsClient("127.0.0.1:%d" % http), space)
                for q in quiet:
                    q.setLevel(logging.CRITICAL)
            finally:
                yamcs.stop()
                for q, level in zip(quiet, levels):
                    q.setLevel(level)
            c = space.relay.coding()
            handed = space.sat.processor.core.counters["tm_frames"]
            in_flight = handed - space.relay.frames
            lost = c["uncorrectable"] or in_flight > 4  # the radio holds 2, the relay 1 or 2
            out("  ground: %d frames decoded, %d channel symbols corrected by Viterbi (the "
                "radio flipped %d bits), %d RS symbols corrected, %d uncorrectable, lock %d, "
                "losses of lock %d" % (c["frames"], c["symbol_errors"], space.radio.down.flipped,
                                       c["corrected"], c["uncorrectable"], c["locks"],
                                       c["losses"]))  # fmt: skip
            out("  frames: %d handed to the radio, %d in Yamcs, %d still on the air: %s" % (
                handed, space.relay.frames, in_flight,
                "FRAMES LOST" if lost else "no frame lost"))  # fmt: skip
            if lost:
                raise RuntimeError("frames were lost on the coded link")
        finally:
            space.close()


def _operate(out, client, space):
    cop1 = client.get_link("obsw", "tc_frames.vc0")
    active = threading.Event()
    sub = cop1.create_cop1_subscription(lambda s: active.set() if s.state == "ACTIVE" else None)
    cop1.initialize_cop1("WITH_CLCW_CHECK", clcw_wait_timeout=20)
    if not active.wait(60):
        raise RuntimeError("COP-1 did not become active over the radio")
    sub.cancel()
    out("  Yamcs: COP-1 active (the CLCW came down in the coded TM)")
    proc = client.get_processor("obsw", "realtime")
    for name in ("angle", "speed"):
        pv = proc.get_parameter_value(MISSION + "/SolarPanel/" + name, from_cache=False,
                                      timeout=60)  # fmt: skip
        out("  HK  %-30s = %-6s (on board: %s)" % (pv.name, pv.eng_value,
                                                   getattr(space.sat.panel, name)))  # fmt: skip
    cmd = proc.create_command_connection().issue(MISSION + "/PUS/ping")
    cmd.await_complete(timeout=60)
    if not cmd.is_success():
        raise RuntimeError("ping failed: %s" % cmd.error)
    out("  TC  /PUS/ping up at 2400 bit/s through COP-1 -> completed")


def _simulated(out):
    from obsw_sim import link_sim

    out("simulated (obsw_sim.link_sim, a simulated clock): HK each second, a 24 kB playback "
        "dump and a 13 kB CFDP downlink, 5 TCs up")  # fmt: skip
    f = link_sim.run(bps=9600, ber=1e-3)
    out("  " + f.summary())
    if f["lost"] or f["link_use"] < 95:
        raise RuntimeError("the simulated link lost packets or idled while data waited")
