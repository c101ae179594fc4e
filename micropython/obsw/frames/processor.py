"""The frame processor: TC from two hot-redundant links in, packets routed by APID; TM out.

Sans-I/O: the host hands it the bytes read from each link with the time, and writes the CADUs
it returns to both links. Routing and the essential-command sink are callables.
"""

from obsw.frames.asm import cadu
from obsw.frames.cltu import CltuDecoder
from obsw.frames.dedup import Deduplicator
from obsw.frames.errors import FecfError, FrameError
from obsw.frames.farm import ACCEPT, Farm1
from obsw.frames.tc import TYPE_BC, Reassembler, Segment, TcFrame, frame_length
from obsw.frames.tm_mux import TmMultiplexer
from obsw.frames.tm_plan import plan_channels
from obsw.frames.tm_plan import tm_plan as make_plan

COUNTERS = (
    "cltus",
    "corrected_bits",
    "cltus_aborted",
    "bad_fecf",
    "invalid_frames",
    "duplicates",
    "accepted",
    "discarded",
    "packets_routed",
    "packets_invalid",
    "essential",
    "tm_packets",
    "tm_dropped",
    "tm_unknown_vc",
    "tm_frames",
    "tc_rejected",
    "tm_spilled",
    "tm_idle_frames",
)


def split_packets(data):
    """Space packets laid end to end in ``data``; returns (packets, leftover byte count)."""
    out = []
    i = 0
    n = len(data)
    while n - i >= 7:
        size = ((data[i + 4] << 8) | data[i + 5]) + 7
        if i + size > n:
            break
        out.append(bytes(data[i : i + size]))
        i += size
    return out, n - i


class FrameProcessor:
    """TC transfer frames in (CLTUs on links 0 and 1), TM transfer frames out.

    ``route(apid, packet)`` receives every telecommand packet; ``essential(unit)`` receives
    what arrives on MAP ``essential_map`` instead (high priority commands). TM packets go in
    with ``send_packet`` and come out of ``tm_output`` as CADUs for both links.

    TM virtual channels: by default those of the plan ``tm_plan`` (``obsw.frames.tm_plan``:
    real-time VC 0, playback VC 1, essential VC 6 unless the dict says otherwise); a packet
    goes on the VC its APID is mapped to in ``tm_vc_of_apid``, else on the real-time VC,
    unless ``send_packet`` names the VC (``send_playback`` names the playback VC). Explicit
    ``tm_channels`` replace the plan's channels (with ``tm_plan`` given too, it still names
    their roles); without a plan, packets whose APID is not mapped go to ``tm_default_vcid``
    (default: the lowest-priority channel) and there is no playback VC.

    TC security: with ``security`` (an ``obsw.frames.sdls.TcSecurity``) every frame but a
    control command is verified after duplicate removal and before FARM-1; a rejected frame is
    counted (``tc_rejected``, and by outcome in ``security.counters``) and each of
    ``rejected_listeners`` is called with (outcome, VC ID, SPI, sequence number). With
    ``tm_security`` (an ``obsw.frames.sdls_gcm.TmSecurity``) the TM frames of the VCs it has
    SAs for are encrypted and authenticated (SDLS AES-GCM).

    The downlink: with ``tm_coding`` (an ``obsw.frames.tm_coding.TmEncoder``) each frame leaves
    channel coded, else as a CADU (ASM and pseudo-randomizer). With ``downlink_bps`` the link is
    a radio of that rate, always transmitting: ``tm_output`` hands out only the frames the
    radio has room for (``obsw.frames.downlink.Downlink``), full frames by VC priority, a
    partly filled one of priority ``tm_urgent`` or higher at once (real-time and essential
    telemetry keep their period), a lower one when the radio would otherwise send idle data,
    and an idle frame only when nothing waits. With ``tm_spill`` (octets) a packet whose VC is
    full waits in a spill store (``tm_spilled``) until the VC has room; when that is full too
    the packet is dropped, counted (``tm_dropped``) and each of ``overflow_listeners`` is called
    with (VC ID, packet), so the host reports it (an event): never a silent drop.
    """

    def __init__(
        self,
        scid,
        route,
        essential=None,
        essential_map=None,
        tc_vcids=(0,),
        segment_header=True,
        tc_randomized=False,
        tm_frame_length=256,
        tm_channels=None,
        tm_vc_of_apid=None,
        tm_plan=None,
        tm_default_vcid=None,
        tm_randomize=True,
        farm_window=10,
        dedup_window=2.0,
        clcw_period=1.0,
        security=None,
        tm_security=None,
        ep=None,
        ep_map=62,
        ep_apid=None,
        tm_coding=None,
        downlink_bps=None,
        tm_urgent=2,
        tm_spill=0,
    ):
        self.scid = scid
        self.route = route
        self.essential = essential
        self.essential_map = essential_map
        self.segment_header = segment_header
        self.tm_randomize = tm_randomize
        self.clcw_period = clcw_period
        if security is not None and security.segment_header != segment_header:
            raise ValueError("TC security and frame processor disagree on segment headers")
        self.security = security
        if ep is not None and not (
            security is not None
            and segment_header
            and [sa for sa in security.sas.values() if sa.map_id == ep_map]
        ):
            raise ValueError("SDLS extended procedures need an SA of their own on MAP %d" % ep_map)
        self.ep = ep  # an obsw.frames.sdls_ep.ExtendedProcedures, or None
        self.ep_map = ep_map
        self.ep_apid = ep_apid
        self._ep_count = 0
        self.rejected_listeners = []  # callables(outcome, vcid, spi, sn)
        self.farms = {}
        self._reassembly = {}
        for v in tc_vcids:
            self.farms[v] = Farm1(v, farm_window)
            self._reassembly[v] = Reassembler()
        self._farm_list = [self.farms[v] for v in sorted(self.farms)]
        self._ocf_next = 0
        self.decoders = [CltuDecoder(tc_randomized), CltuDecoder(tc_randomized)]
        self.dedup = Deduplicator(dedup_window)
        plan = None
        if tm_channels is None or tm_plan is not None:
            plan = make_plan(tm_plan)
            if tm_channels is None:
                tm_channels = plan_channels(plan)
            if tm_default_vcid is None:
                tm_default_vcid = plan["realtime"]
        self.tm_plan = plan
        self.mux = TmMultiplexer(
            scid, tm_frame_length, tm_channels, self._ocf, security=tm_security
        )
        self.tm_vc_of_apid = tm_vc_of_apid or {}
        if tm_default_vcid is None:
            tm_default_vcid = self.mux.channels[-1].vcid if tm_channels else 0
        self.tm_default_vcid = tm_default_vcid
        self.playback_vcid = self.tm_plan["playback"] if self.tm_plan is not None else None
        self.counters = {}
        for name in COUNTERS:
            self.counters[name] = 0
        self._report = True  # send a CLCW soon
        self._last_tm = None
        self.tm_coding = tm_coding
        self.downlink = None
        if downlink_bps:
            from obsw.frames.downlink import Downlink

            octets = tm_coding.channel_length if tm_coding is not None else tm_frame_length + 4
            self.downlink = Downlink(downlink_bps, octets)
        self.tm_urgent = tm_urgent
        self.spill = None
        if tm_spill:
            from obsw.frames.downlink import Spill

            self.spill = Spill(tm_spill)
        self.overflow_listeners = []  # callables(vcid, packet)

    def _count(self, name, n=1):
        self.counters[name] += n

    # -- telecommand ------------------------------------------------------------------------

    def receive(self, link, data, now):
        """Bytes read from link 0 or 1."""
        dec = self.decoders[link]
        before = (dec.corrected, dec.aborted)
        for block_data in dec.feed(data):
            self._count("cltus")
            self.on_frame_data(link, block_data, now)
        self._count("corrected_bits", dec.corrected - before[0])
        self._count("cltus_aborted", dec.aborted - before[1])

    def on_frame_data(self, link, data, now):
        """The data of one decoded CLTU (frame plus fill)."""
        try:
            n = frame_length(data)
            frame = TcFrame.unpack(data, trailing=True)
        except FecfError:
            self._count("bad_fecf")
            return
        except FrameError:
            self._count("invalid_frames")
            return
        farm = self.farms.get(frame.vcid)
        if frame.scid != self.scid or farm is None or frame.frame_type == 1:
            self._count("invalid_frames")
            return
        if self.dedup.duplicate(bytes(data[:n]), link, now):
            self._count("duplicates")
            return
        self._report = True
        sa = None
        if self.security is not None and frame.frame_type != TYPE_BC:
            outcome, sa, sn, clear = self.security.process(data, n)
            if clear is None:
                self._rejected(outcome, frame.vcid, sa, sn, data, n)
                return
            frame.data = clear
        if farm.on_frame(frame) != ACCEPT:
            self._count("discarded")
            return
        if sa is not None:
            self.security.commit(sa, sn)
        self._count("accepted")
        while True:
            accepted = farm.take()
            if accepted is None:
                break
            if accepted.frame_type != TYPE_BC:
                self._deliver(accepted)

    def _rejected(self, outcome, vcid, sa, sn, data, n):
        self._count("tc_rejected")
        if sa is not None:
            spi = sa.spi
        else:
            at = 6 if self.segment_header else 5
            spi = (data[at] << 8) | data[at + 1] if n >= at + 2 else 0
        for fn in self.rejected_listeners:
            fn(outcome, vcid, spi, sn)

    def _deliver(self, frame):
        data = frame.data
        if self.segment_header:
            try:
                seg = Segment.unpack(data)
            except FrameError:
                self._count("packets_invalid")
                return
            if self.essential_map is not None and seg.map_id == self.essential_map:
                unit = self._reassembly[frame.vcid].push(seg)
                if unit is not None:
                    self._count("essential")
                    if self.essential is not None:
                        self.essential(unit)
                return
            if self.ep is not None and seg.map_id == self.ep_map:
                self._extended_procedures(frame.vcid, seg)
                return
            data = self._reassembly[frame.vcid].push(seg)
            if data is None:
                return
        packets, leftover = split_packets(data)
        if leftover:
            self._count("packets_invalid")
        for p in packets:
            self._count("packets_routed")
            self.route(((p[0] & 7) << 8) | p[1], p)

    def _extended_procedures(self, vcid, seg):
        """EP PDUs (frame data on the EP SA's MAP, which only that SA can secure): run them and
        send the replies in a TM space packet on ``ep_apid``."""
        unit = self._reassembly[vcid].push(seg)
        if unit is None:
            return
        reply = self.ep.handle(unit)
        if self.ep_apid is None:
            return
        n = len(reply) - 1
        head = bytes(
            (
                self.ep_apid >> 8,
                self.ep_apid & 0xFF,
                0xC0 | (self._ep_count >> 8) & 0x3F,
                self._ep_count & 0xFF,
                n >> 8,
                n & 0xFF,
            )
        )
        self._ep_count = (self._ep_count + 1) & 0x3FFF
        self.send_packet(head + reply)

    # -- telemetry --------------------------------------------------------------------------

    def _ocf(self):
        if not self._farm_list:
            return None
        farm = self._farm_list[self._ocf_next % len(self._farm_list)]
        self._ocf_next += 1
        return farm.clcw().pack()

    def send_packet(self, packet, vcid=None):
        """Queue a TM packet, unchanged, on virtual channel ``vcid`` (by default the one its
        APID is mapped to); False when the channel is full or not configured (counted)."""
        if vcid is None:
            apid = ((packet[0] & 7) << 8) | packet[1] if len(packet) >= 2 else 0
            vcid = self.tm_vc_of_apid.get(apid, self.tm_default_vcid)
        try:
            channel = self.mux.channel(vcid)
        except KeyError:
            self._count("tm_unknown_vc")
            return False
        spill = self.spill
        if spill is not None and (spill.waiting(vcid) or channel.room() < len(packet)):
            if spill.put(vcid, bytes(packet)):
                self._count("tm_packets")
                self._count("tm_spilled")
                return True
        elif channel.push(packet):
            self._count("tm_packets")
            return True
        self._count("tm_dropped")
        for fn in self.overflow_listeners:
            fn(vcid, packet)
        return False

    def send_playback(self, packet):
        """Queue a packet retrieved from a packet store on the plan's playback VC."""
        if self.playback_vcid is None:
            self._count("tm_unknown_vc")
            return False
        return self.send_packet(packet, self.playback_vcid)

    def tm_output(self, now, flush=True):
        """CADUs to write to both links: full frames by priority, then (with ``flush``) the
        rest padded with idle data, and an idle frame with the CLCW when one is due; with
        ``downlink_bps``, what the radio has room for now (see the class)."""
        if self.downlink is not None:
            return self._paced(now)
        out = []
        while True:
            f = self.mux.frame(flush)
            if f is None:
                break
            out.append(f)
        due = self._report or self._last_tm is None or now - self._last_tm >= self.clcw_period
        if not out and due:
            out.append(self.mux.frame(False, True))
        if out:
            self._report = False
            self._last_tm = now
        self._count("tm_frames", len(out))
        return [self._channel(f) for f in out]

    def _channel(self, frame):
        if self.tm_coding is not None:
            return self.tm_coding.encode(frame.pack())
        return cadu(frame.pack(), self.tm_randomize)

    def _paced(self, now):
        out = []
        mux = self.mux
        for _ in range(self.downlink.due(now)):
            if self.spill is not None:
                self.spill.refill(mux)
            f = mux.frame(True, False, self.tm_urgent)
            if f is None:
                f = mux.frame(True)
            if f is None:
                f = mux.frame(False, True)
                self._count("tm_idle_frames")
            out.append(self._channel(f))
        if out:
            self._report = False
            self._last_tm = now
            self._count("tm_frames", len(out))
        return out
