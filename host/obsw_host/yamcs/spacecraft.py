"""The sample spacecraft next to Yamcs: the OBC's processes and the link Yamcs talks to.

``SampleSpacecraft(sdb_path, root, mode)`` runs, in this process, the on-board PUS process
with the sample solar panel (``obsw_host.pus.onboard.Onboard``), the on-board CFDP entity
(``obsw_host.cfdp.link.UdpEntity``, files under ``root``) and, for ``mode``:
- ``packets``: the packet gateway (Yamcs' TCP packet links <-> the processes' UDP);
- ``frames``: the frame processor (``obsw_host.frames.processor.FrameProcessorHost``) with
  link A on UDP: CLTUs from Yamcs in, TM frames out to Yamcs' frame link (link B idle); TC
  frames without segment header (the MAP service), TM frames not randomized; with ``keys``
  (an SDLS key file) TC and TM frames are protected as its SAs say. With ``coding`` (a
  ``obsw_host.frames.coding.LinkSettings``) the TM leaves channel coded and paced to its
  downlink rate, unchanged on UDP to ``tm_frames_port`` (a radio, then a
  ``obsw_host.frames.relay.FrameRelay`` in front of Yamcs).
``ports()`` gives the ground ports to write into the Yamcs instance. Everything listens on
127.0.0.1 only; ports are chosen by the system unless ``ports`` gives them (``pus``,
``cfdp``: the gateway's TCP ports; ``cltu``: the frame processor's UDP port for CLTUs).
"""

import collections
import concurrent.futures
import os
import socket
import threading
import time

from obsw.cfdp.entity import CfdpEntity
from obsw.cfdp.mib import Mib, RemoteEntity
from obsw.crc import CHECKSUM_MODULAR
from obsw.spp import TYPE_TM

from obsw_host.cfdp.filestore import RootedFilestore
from obsw_host.cfdp.link import UdpEntity
from obsw_host.mission.ids import MissionIds
from obsw_host.pus.onboard import Onboard
from obsw_host.solar_panel import SOLAR_PANEL, SolarPanel
from obsw_host.yamcs.gateway import PacketGateway

LOOPBACK = "127.0.0.1"
ASM = b"\x1a\xcf\xfc\x1d"


class UdpFrameLink:
    """A frame processor link on UDP: reads what Yamcs sends, writes to ``peer``.

    ``drop(data)`` (optional) returns True for a datagram to lose on the way in, to show
    COP-1 recovering a lost frame. What goes out is a CADU less its attached sync marker: the
    ground station's frame synchroniser hands Yamcs one transfer frame per datagram. With
    ``raw`` what goes out is unchanged (channel-coded octets for a radio and a ``FrameRelay``).
    """

    def __init__(self, peer, port=0, drop=None, raw=False):
        self.name = "udp"
        self.skip = 0 if raw else len(ASM)
        self.peer = peer
        self.drop = drop
        self.enabled = True
        self.dropped = 0
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind((LOOPBACK, port))
        self.sock.setblocking(False)
        self.address = self.sock.getsockname()

    def fileno(self):
        return self.sock.fileno()

    def read(self):
        try:
            data = self.sock.recv(65536)
        except OSError:
            return b""
        if self.drop is not None and self.drop(data):
            self.dropped += 1
            return b""
        return data

    def write(self, data):
        if self.enabled and self.peer is not None:
            try:
                self.sock.sendto(data[self.skip :], self.peer)
            except OSError:
                pass  # nobody listening yet: the frame is lost, as on a radio link

    def close(self):
        self.sock.close()


class SampleSpacecraft:
    """The sample OBC processes and the link Yamcs uses (see the module text)."""

    def __init__(
        self,
        sdb_path,
        root,
        mode="packets",
        period=0.1,
        tm_frames_port=None,
        drop=None,
        sat_entity=None,
        ground_entity=None,
        ports=None,
        ids=None,
        keys=None,
        key_state=None,
        coding=None,
    ):
        ports = ports or {}
        self.mode = mode
        self.ids = ids = ids or MissionIds.locate(sdb=sdb_path)
        self.sdb = ids.sdb
        self.panel = SolarPanel()
        # the sample's panel when the database has it; another mission's own components run
        # in its OBC (`obsw yamcs run --obc`)
        has_panel = SOLAR_PANEL.name in self.sdb.components
        components = [(SOLAR_PANEL, self.panel)] if has_panel else []
        self.root = root
        os.makedirs(root, exist_ok=True)
        self._stop = threading.Event()
        self._threads = []
        self._requests = collections.deque()
        self.onboard = None
        self.gateway = None
        self.processor = None
        self.cfdp = None
        sat = sat_entity or ids.cfdp_entities[0]
        ground = ground_entity or ids.cfdp_entities[1]
        cfdp_apid = ids.apid("cfdp")
        self.ground_entity = ground
        try:
            if mode == "packets":
                self.gateway = PacketGateway(
                    tcp_ports={"pus": ports.get("pus", 0), "cfdp": ports.get("cfdp", 0)},
                    apids={"cfdp": [cfdp_apid]},
                    tm_port=0,
                )
                tm_input = self.gateway.tm_address
            elif mode == "frames":
                from obsw.frames.tm_mux import TmVirtualChannel
                from obsw.frames.tm_plan import plan_channels

                from obsw_host.frames.processor import FrameProcessorHost

                plan = ids.tm_vcs
                cfdp_vc = ids.cfdp_vc
                channels = plan_channels(plan) + [TmVirtualChannel(cfdp_vc, 0, 1 << 20, "cfdp")]
                peer = (LOOPBACK, tm_frames_port) if tm_frames_port else None
                self.link_a = UdpFrameLink(
                    peer, ports.get("cltu", 0), drop=drop, raw=coding is not None
                )
                self.link_b = UdpFrameLink(None)
                self.link_b.enabled = False
                options = {}
                if keys is not None:  # SDLS on TC and TM (AES-GCM SAs of the key file)
                    from obsw_host.frames.processor import security_options

                    options = security_options(keys, self.sdb, key_state, segment_header=False)
                if coding is not None:
                    options.update(
                        tm_coding=coding.encoder(),
                        downlink_bps=coding.downlink_bps,
                        tm_spill=coding.tm_spill,
                    )
                self.processor = FrameProcessorHost(
                    self.link_a,
                    self.link_b,
                    ids.scid,
                    tm_port=0,
                    vc_ports={},
                    tm_channels=channels,
                    tm_plan=plan,
                    tm_vc_of_apid={cfdp_apid: cfdp_vc},
                    tc_vcids=(ids.tc_vc,),
                    tm_randomize=False,
                    segment_header=False,
                    clcw_period=0.2,
                    **options,
                )
                tm_input = (LOOPBACK, self.processor.tm_port)
            else:
                raise ValueError("link mode %r, expected 'packets' or 'frames'" % (mode,))
            self.onboard = Onboard(
                self.sdb,
                port=0,
                period=period,
                tm_to=tm_input,
                components=components,
                apid=ids.pus_apid,
                config=ids.pus_config,
            )
            remote = RemoteEntity(
                ground,
                checksum=CHECKSUM_MODULAR,
                max_segment=400,
                ack_interval=1.0,
                ack_limit=10,
                nak_interval=1.0,
                nak_limit=10,
                inactivity=30.0,
                check_interval=1.0,
            )
            entity = CfdpEntity(Mib(sat, [remote]), RootedFilestore(root), persist=False)
            self.cfdp = UdpEntity(
                entity, (LOOPBACK, 0), {ground: tm_input}, apid=cfdp_apid, packet_type=TYPE_TM
            )
            self.indications = []
            self._indicated = threading.Condition()
            self.cfdp.on_indication = self._indication
        except Exception:
            self.close()
            raise
        self.cfdp_apid = cfdp_apid

    def ports(self):
        """The ground-side ports of the link, for ``instance.write_instance(ports=...)``."""
        if self.mode == "packets":
            return dict(self.gateway.ports)
        return {"cltu": self.link_a.address[1]}

    def start(self):
        """Run every process in daemon threads; returns self."""
        self.onboard.start()
        routes = {self.onboard.apid: self.onboard.address[:2]}
        routes[self.cfdp_apid] = self.cfdp.address[:2]
        if self.gateway is not None:
            self.gateway.routes.update(routes)
            self.gateway.start()
        else:
            self._route_frames(routes)
            self._spawn(self.processor.step, "frame-processor")
        self._spawn(self._cfdp_step, "cfdp-entity")
        return self

    def _cfdp_step(self):
        while self._requests:
            fn, fut = self._requests.popleft()
            try:
                fut.set_result(fn())
            except Exception as e:
                fut.set_exception(e)
        self.cfdp.step(0.02)

    def call_cfdp(self, fn, timeout=10.0):
        """Run ``fn(entity)`` in the CFDP entity's thread; returns its value."""
        fut = concurrent.futures.Future()
        self._requests.append((lambda: fn(self.cfdp.entity), fut))
        return fut.result(timeout)

    def _route_frames(self, routes):
        self.processor.routes.update(routes)

    def set_tm_frames_peer(self, port):
        """Where TM frames go (Yamcs' frame link UDP port)."""
        self.link_a.peer = (LOOPBACK, port)

    def _spawn(self, step, name):
        def loop():
            while not self._stop.is_set():
                step()

        t = threading.Thread(target=loop, name=name, daemon=True)
        t.start()
        self._threads.append(t)

    def put(self, name, dest_name=None, mode=None):
        """Send file ``name`` (under ``root``) to the ground entity; returns the transaction id."""
        return self.call_cfdp(
            lambda ent: ent.put(
                self.ground_entity, name, dest_name or name, mode=mode, now=time.monotonic()
            )
        )

    def _indication(self, ind):
        with self._indicated:
            self.indications.append(ind)
            self._indicated.notify_all()

    def wait_finished(self, tid=None, role=None, timeout=30.0, count=1):
        """The ``count``-th 'finished' indication of ``tid`` / ``role``; None after ``timeout``
        seconds."""
        with self._indicated:
            self._indicated.wait_for(lambda: len(self.finished(tid, role)) >= count, timeout)
            found = self.finished(tid, role)
        return found[count - 1] if len(found) >= count else None

    def finished(self, tid=None, role=None):
        """The 'finished' indications so far (of ``tid``, of ``role`` 'S' or 'R')."""
        return [
            i
            for i in list(self.indications)
            if i.kind == "finished"
            and (tid is None or i.tid == tid)
            and (role is None or i.info.get("role") == role)
        ]

    def close(self):
        self._stop.set()
        for t in self._threads:
            t.join(5)
        self._threads = []
        for part in (self.onboard,):
            if part is not None:
                part.stop()
        for part in (self.gateway, self.processor, self.cfdp):
            if part is not None:
                part.close()

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.close()
