"""The sample spacecraft behind a slow, noisy radio, with Yamcs' frame link on the ground.

``YamcsSpaceLink(sdb_path, root, link, tm_frames_port)`` runs the sample spacecraft in frame
mode with the mission's TM coding and downlink rate (``link``, an
``obsw_host.frames.coding.LinkSettings``), the radio model of ``obsw_sim.radio`` (its rates,
bit errors or Eb/N0, bursts and slips from ``link.radio``) and a ``FrameRelay`` that decodes
the channel and hands Yamcs plain TM frames on ``tm_frames_port``; Yamcs' CLTUs go up through
the relay and the radio. ``ports()`` are the ports to write into the Yamcs instance.

    OBC frame processor --UDP--> radio (rate, noise) --UDP int8--> FrameRelay --UDP--> Yamcs
                        <--UDP--                     <--UDP-------            <--UDP--
"""

import threading

from obsw_host.frames.radio import UdpLink
from obsw_host.frames.relay import FrameRelay
from obsw_host.yamcs.spacecraft import LOOPBACK, SampleSpacecraft

from obsw_sim.radio import RadioLink


class YamcsSpaceLink:
    """The sample spacecraft, the radio and the relay (see the module)."""

    def __init__(self, sdb_path, root, link, tm_frames_port, seed=None, **options):
        self.link = link
        self.sat = SampleSpacecraft(sdb_path, root, "frames", coding=link, **options)
        self.radio = None
        self.relay = None
        try:
            soft = link.radio.get("ebn0_db") is not None
            self.station_link = UdpLink(0, "int8" if soft else "octets")
            self.relay = FrameRelay([self.station_link], link.decoder, (LOOPBACK, tm_frames_port))
            self.radio = RadioLink.from_mission(
                link, None, self.station_link.address, seed=seed,
                space_peer=self.sat.link_a.address,
            )  # fmt: skip
        except Exception:
            self.close()
            raise
        self.sat.link_a.peer = self.radio.space_address
        self.station_link.peer = self.radio.address
        self._stop = threading.Event()
        self._thread = None

    def ports(self):
        """The ground ports of the link, for ``instance.write_instance(ports=...)``."""
        return {"cltu": self.relay.cltu_address[1]}

    def start(self):
        self.sat.start()
        self.radio.start()
        self._thread = threading.Thread(target=self.relay.run, args=(self._stop,),
                                        name="relay", daemon=True)  # fmt: skip
        self._thread.start()
        return self

    def close(self):
        self._stop.set()
        if self._thread is not None:
            self._thread.join(2)
        if self.radio is not None:
            self.radio.stop()
        if self.relay is not None:
            self.relay.close()
        self.sat.close()
