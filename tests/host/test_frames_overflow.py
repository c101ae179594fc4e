"""A TM packet the frame processor cannot keep is reported to the ground as event
frames.tm_overflow (VC ID, length) on the frame processor's own APID, never dropped silently."""

import struct

from obsw.frames.asm import CaduDecoder
from obsw.frames.tm import TmFrame
from obsw.frames.tm_demux import TmDemultiplexer
from obsw.frames.tm_mux import TmVirtualChannel
from obsw.pus.tm import PusTm
from obsw.spp import SpacePacket
from obsw_host.frames.links import FdLink, open_pty_pair
from obsw_host.frames.processor import FrameProcessorHost, sdb_events
from obsw_host.mission.ids import event_id
from obsw_host.sample import load_sdb

LENGTH = 128


def test_overflow_becomes_an_event():
    sdb = load_sdb()
    overflow = event_id(sdb, "frames.tm_overflow")
    event_apid, event_ids = sdb_events(sdb)
    pairs = [open_pty_pair(), open_pty_pair()]
    links = [FdLink(c, n) for (c, _), n in zip(pairs, "AB")]
    channels = [TmVirtualChannel(0, 2, 4096, "realtime"), TmVirtualChannel(1, 1, 100, "store")]
    now = [0.0]
    fp = FrameProcessorHost(
        links[0], links[1], 0x42, tm_port=0, vc_ports={}, tm_channels=channels,
        tm_frame_length=LENGTH, tm_spill=60, event_apid=event_apid, event_ids=event_ids,
        overflow_event=overflow, clock=lambda: now[0], tm_default_vcid=0,
    )  # fmt: skip
    try:
        packet = SpacePacket(0, 0x30, bytes(44)).pack()  # 50 octets
        kept = [fp.core.send_packet(packet, 1) for _ in range(5)]
        assert kept == [True, True, True, False, False]  # 2 in the VC, 1 spilled, 2 dropped
        assert fp.core.counters["tm_dropped"] == 2
        frames = fp.core.tm_output(0.0)
        dec = CaduDecoder(LENGTH)
        demux = TmDemultiplexer(0x42)
        events = []
        for cadu in frames:
            for raw in dec.feed(cadu):
                for p in demux.on_frame(TmFrame.unpack(raw)):
                    if (((p[0] & 7) << 8) | p[1]) == event_apid:
                        events.append(PusTm.unpack(p))
        assert len(events) == 2
        for tm in events:
            assert (tm.service, tm.subtype) == (5, 3)
            assert tm.data[-5:] == struct.pack(">HBH", overflow, 1, 50)[-5:]
    finally:
        fp.close()
