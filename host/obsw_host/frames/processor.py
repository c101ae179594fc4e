"""The frame processor process: two serial links to the COM module, UDP to the applications.

Telecommand packets go to the UDP address their APID has in ``routes`` (APID -> (host, port),
e.g. a mission's ``Ports.routes``), else to ``default_route(apid)`` (default: the run's
``Ports.for_apid`` on ``host``), sent from the ``tm_port`` socket, so an application answering
the sender reaches the TM input; a packet with no route is counted (``unrouted``); telemetry
packets sent to ``tm_port`` (default: the ports module's ``tm``, base - 1) leave as TM frames
on both links, on the VC of their APID (the real-time VC unless mapped). Each entry of
``vc_ports`` (VC ID -> UDP port) is one more input whose packets all go on that VC, unchanged:
by default the playback VC of the plan on ``tm_port + 1`` (the ports module's ``playback``),
where the PUS application process sends what service 15 retrieves from its packet stores.

TC security: with ``security`` (an ``obsw.frames.sdls.TcSecurity``, see
``obsw_host.frames.keys``) every TC frame is authenticated before FARM-1. A rejected frame is
counted and, with ``event_apid``, reported to ground as a PUS service 5 event (TM[5,3], medium
severity, aux: VC ID u8, SPI u16, sequence number u64) of the frame processor's own application
process, which also serves TCs to that APID (e.g. TC[5,6] to disable an event). At most
``event_limit`` such reports go out per second; the others are counted (``events_limited``).
``state`` (a ``keys.StateFile``) saves the sequence numbers each time a frame is accepted.

The downlink (``tm_coding``, ``downlink_bps``, ``tm_spill``: see ``obsw.frames.processor``):
a TM packet that finds its virtual channel and the spill store full is reported, with
``overflow_event`` (an event ID), as a PUS event of that APID (TM[5,3], aux: VC ID u8, packet
length u16), within the same ``event_limit``; it is counted (``tm_dropped``) in every case.
"""

import os
import select
import socket
import struct
import time

from obsw.frames.processor import FrameProcessor
from obsw.frames.sdls import EVENT_IDS, OUTCOME_NAMES
from obsw.pus.app import ApplicationProcess
from obsw.pus.services.s05_events import EventReporting

from obsw_host.frames.links import SerialLink
from obsw_host.mission.ports import Ports
from obsw_host.net import DEFAULT_HOST


def sdb_events(sdb):
    """(event APID, event IDs by outcome) of the frame processor in a spacecraft database: its
    'frames' APID and the events named frames.tc_<outcome>."""
    ids = [0] + [sdb.event("frames.tc_" + name).id for name in OUTCOME_NAMES[1:]]
    return sdb.apid("frames"), tuple(ids)


def security_options(key_path, sdb, state_path=None, segment_header=True):
    """The FrameProcessorHost options that authenticate TC frames with the key file at
    ``key_path`` and report rejections as the events of ``sdb`` (a spacecraft database)."""
    from obsw_host.frames import keys

    security, tm_security, state = keys.load_all(key_path, state_path, segment_header)
    event_apid, event_ids = sdb_events(sdb)
    ep = {}
    store_path = keys.keystore_path(key_path)
    has_ep_sa = [sa for sa in security.sas.values() if sa.map_id == keys.EP_MAP]
    if segment_header and has_ep_sa and os.path.exists(store_path):
        from obsw.frames.sdls_ep import ExtendedProcedures

        engine = ExtendedProcedures(keys.load_keystore(store_path), security, tm_security)
        sas = list(security.sas.values()) + (
            list(tm_security.sas.values()) if tm_security is not None else []
        )

        def save():  # keys and SA states survive power cycles: both files replaced atomically
            keys.save_keystore(store_path, engine.store)
            keys.write_sas(key_path, sas, replace=True)
            if state is not None:
                state.save()

        engine.on_change = save
        ep = {"ep": engine, "ep_map": keys.EP_MAP, "ep_apid": event_apid}
    return {
        **ep,
        "security": security,
        "tm_security": tm_security,
        "state": state,
        "event_apid": event_apid,
        "event_ids": event_ids,
    }


class _Clock:
    def __init__(self, fn):
        self.now = fn


class FrameProcessorHost:
    """Runs the core FrameProcessor on two links (SerialLink-like objects or device paths)."""

    def __init__(
        self,
        link_a,
        link_b,
        scid,
        host=DEFAULT_HOST,
        routes=None,
        default_route=None,
        tm_port=None,
        essential_port=None,
        vc_ports=None,
        clock=time.monotonic,
        security=None,
        state=None,
        event_apid=None,
        event_ids=EVENT_IDS,
        event_limit=10,
        overflow_event=None,
        **options,
    ):
        self.links = [
            SerialLink(link) if isinstance(link, str) else link for link in (link_a, link_b)
        ]
        self.host = host
        ports = Ports()
        self.routes = dict(routes or {})
        self.default_route = ports.route(host) if default_route is None else default_route
        self.unrouted = 0  # TC packets whose APID has no route
        tm_port = ports.tm if tm_port is None else tm_port
        self.essential_port = essential_port
        self.clock = clock
        self.essential = []
        self.core = FrameProcessor(
            scid, self._route, self._essential, security=security, **options
        )
        self.state = state
        self.event_ids = event_ids
        self.event_limit = event_limit
        self.events_limited = 0
        self._event_window = (None, 0)  # (second, reports in it)
        self.pus = None
        if event_apid is not None:
            self.pus = ApplicationProcess(event_apid, self.core.send_packet, _Clock(clock))
            known = [i for i in event_ids if i] + ([overflow_event] if overflow_event else [])
            self.pus.register(EventReporting(known=known))
        self.core.rejected_listeners.append(self._rejected)
        self.overflow_event = overflow_event
        self._overflowing = False
        self.core.overflow_listeners.append(self._overflow)
        self._accepted = 0
        if vc_ports is None:
            pb = self.core.playback_vcid
            vc_ports = {} if pb is None else {pb: tm_port + 1 if tm_port else 0}
        self.tm = self._bind(tm_port)
        self.out = self.tm
        self.tm_port = self.tm.getsockname()[1]
        self.vc_inputs = {}  # socket -> VC ID
        self.vc_ports = {}  # VC ID -> bound UDP port
        try:
            for vcid, port in vc_ports.items():
                try:
                    self.core.mux.channel(vcid)
                except KeyError:
                    raise ValueError(
                        "no TM virtual channel %r for UDP port %d" % (vcid, port)
                    ) from None
                s = self._bind(port)
                self.vc_inputs[s] = vcid
                self.vc_ports[vcid] = s.getsockname()[1]
        except (OSError, ValueError):
            self.close()
            raise

    @property
    def playback_port(self):
        """The UDP port whose packets go on the playback VC (None without one)."""
        return self.vc_ports.get(self.core.playback_vcid)

    def _bind(self, port):
        s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        s.bind((self.host, port))
        s.setblocking(False)
        return s

    def _rejected(self, outcome, vcid, spi, sn):
        self._event(self.event_ids[outcome], struct.pack(">BHQ", vcid, spi, sn))

    def _overflow(self, vcid, packet):
        if self._overflowing:  # the report itself found no room: counted, not reported again
            return
        self._overflowing = True
        try:
            self._event(self.overflow_event, struct.pack(">BH", vcid, len(packet)))
        finally:
            self._overflowing = False

    def _event(self, event_id, aux):
        if self.pus is None or not event_id:
            return
        second = int(self.clock())
        start, n = self._event_window
        if start != second:
            start, n = second, 0
        if n >= self.event_limit:
            self.events_limited += 1
            return
        self._event_window = (start, n + 1)
        self.pus.event(event_id, 3, aux)

    def _route(self, apid, packet):
        if self.pus is not None and apid == self.pus.apid:
            self.pus.receive(packet)
            return
        address = self.routes.get(apid)
        if address is None and self.default_route:
            address = self.default_route(apid)
        if address is None:
            self.unrouted += 1
            return
        try:
            self.out.sendto(packet, address)
        except OSError:
            pass  # nobody listening: UDP drops it, as the thesis' processes expect

    def _essential(self, unit):
        self.essential.append(unit)
        if self.essential_port is not None:
            self.out.sendto(unit, (self.host, self.essential_port))

    def step(self, timeout=0.05):
        """Wait up to ``timeout`` for input, process it, write due telemetry to both links."""
        inputs = self.links + [self.tm] + list(self.vc_inputs)
        waiting = [link for link in self.links if getattr(link, "queue", None) and link.pending()]
        readable, writable, _ = select.select(inputs, waiting, [], timeout)
        for link in writable:  # a queued link's UART drained: write what waits
            link.flush()
        now = self.clock()
        for i, link in enumerate(self.links):
            if link in readable:
                data = link.read()
                if data and link.enabled:
                    self.core.receive(i, data, now)
        if self.state is not None and self.core.counters["accepted"] != self._accepted:
            self._accepted = self.core.counters["accepted"]
            self.state.save()
        if self.tm in readable:
            while True:
                try:
                    packet = self.tm.recv(65542)
                except OSError:  # nothing more (or an ICMP error from a TC sent earlier)
                    break
                self.core.send_packet(packet)
        for s, vcid in self.vc_inputs.items():
            if s in readable:
                while True:
                    try:
                        packet = s.recv(65542)
                    except OSError:
                        break
                    self.core.send_packet(packet, vcid)
        for cadu in self.core.tm_output(now):
            for link in self.links:
                link.write(cadu)

    def run(self, stop=None, duration=None):
        end = None if duration is None else self.clock() + duration
        while not (stop is not None and stop.is_set()) and (end is None or self.clock() < end):
            self.step()

    def close(self):
        for link in self.links:
            link.close()
        self.tm.close()
        for s in self.vc_inputs:
            s.close()
