"""Yamcs operates the sample spacecraft over a slow, noisy radio: TM with concatenated coding
at 9,600 bit/s and a bit error rate of 1e-3, decoded by the FrameRelay in front of Yamcs'
frame link; TCs go up through Yamcs' COP-1 at 2,400 bit/s. Housekeeping reaches Yamcs, a ping
completes, symbol errors were corrected, no frame was lost. Skipped without Java or Yamcs."""

import socket
import threading
import time

import pytest
from obsw_host.frames.coding import LinkSettings
from obsw_host.sample import SDB_PATH
from obsw_host.yamcs import database, instance, server

MISSING = server.missing()
pytestmark = pytest.mark.skipif(MISSING is not None, reason=str(MISSING))
MISSION = "/obsw-demo"
TIMEOUT = 60.0


def free_port(kind=socket.SOCK_STREAM):
    s = socket.socket(socket.AF_INET, kind)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


SETTINGS = {
    "tm_frame_length": 256,
    "tm_coding": {"scheme": "concatenated", "interleave": 2},
    "downlink_bps": 9600,
    "uplink_bps": 2400,
    "radio": {"ber": 1e-3, "seed": 3},
}


def test_yamcs_over_the_coded_noisy_link(tmp_path):
    from obsw_sim.spacelink import YamcsSpaceLink
    from yamcs.client import YamcsClient

    link = LinkSettings(SETTINGS)
    tm_frames = free_port(socket.SOCK_DGRAM)
    space = YamcsSpaceLink(SDB_PATH, str(tmp_path / "sat"), link, tm_frames)
    http = free_port()
    folder = str(tmp_path)
    try:
        instance.write_instance(folder, database.load(SDB_PATH), "frames",
                                dict(space.ports(), tm_frames=tm_frames), http)  # fmt: skip
        space.start()
        yamcs = server.Yamcs(folder, http).start(timeout=120)
        try:
            client = YamcsClient("127.0.0.1:%d" % http)
            cop1 = client.get_link("obsw", "tc_frames.vc0")
            active = threading.Event()
            sub = cop1.create_cop1_subscription(
                lambda s: active.set() if s.state == "ACTIVE" else None
            )
            cop1.initialize_cop1("WITH_CLCW_CHECK", clcw_wait_timeout=20)
            assert active.wait(TIMEOUT), "COP-1 did not become active"
            sub.cancel()
            proc = client.get_processor("obsw", "realtime")
            pv = proc.get_parameter_value(MISSION + "/SolarPanel/angle", from_cache=False,
                                          timeout=TIMEOUT)  # fmt: skip
            assert pv is not None and pv.eng_value == space.sat.panel.angle
            cmd = proc.create_command_connection().issue(MISSION + "/PUS/ping")
            cmd.await_complete(timeout=TIMEOUT)
            assert cmd.is_success(), cmd.error
            # enough frames on the air for the coding figures to mean something, however fast
            # Yamcs came up
            deadline = time.monotonic() + TIMEOUT
            while space.relay.frames <= 10 and time.monotonic() < deadline:
                time.sleep(0.1)
        finally:
            yamcs.stop()
        coding = space.relay.coding()
        assert coding["symbol_errors"] > 0  # the radio flipped bits, Viterbi corrected them
        assert coding["uncorrectable"] == 0 and coding["losses"] == 0 and coding["locks"] == 1
        assert space.radio.down.flipped > 0
        assert space.sat.processor.core.counters["tm_dropped"] == 0
        assert space.relay.cltus >= 1  # at least the ping's AD frame came up through it
        # every frame handed to the radio reached Yamcs but those still on the air (the radio
        # holds one beyond the one it sends) or in the relay
        handed = space.sat.processor.core.counters["tm_frames"]
        assert space.relay.frames > 10 and handed - space.relay.frames <= 4
    finally:
        space.close()
