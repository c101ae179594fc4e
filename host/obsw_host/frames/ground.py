"""The ground end of the link: FOP-1 and CLTU encoding up, TM frame decoding down."""

import select
from collections import deque

from obsw.frames import fop as F
from obsw.frames.asm import CaduDecoder
from obsw.frames.cltu import encode
from obsw.frames.dedup import Deduplicator
from obsw.frames.errors import FrameError
from obsw.frames.tc import Segment
from obsw.frames.tm import TmFrame
from obsw.frames.tm_demux import TmDemultiplexer

CODING_COUNTERS = ("frames", "corrected", "symbol_errors", "uncorrectable", "locks", "losses",
                   "slips")  # fmt: skip


class CodedInput:
    """A TmDecoder with a CaduDecoder's ``feed``: frames whose codeblock could be decoded."""

    def __init__(self, decoder, soft):
        self.decoder = decoder
        self.feed_input = decoder.feed_soft if soft else decoder.feed_octets

    def feed(self, data):
        return [f.data for f in self.feed_input(data) if f.data is not None]

    def counters(self):
        d, s = self.decoder, self.decoder.sync
        return {"frames": d.frames - d.uncorrectable, "corrected": d.corrected,
                "symbol_errors": d.symbol_errors, "uncorrectable": d.uncorrectable,
                "locks": s.locks, "losses": s.losses, "slips": s.slips}  # fmt: skip


def coding_counters(decoders):
    """The counters of the ``CodedInput`` among ``decoders``, summed."""
    out = dict.fromkeys(CODING_COUNTERS, 0)
    for d in decoders:
        if isinstance(d, CodedInput):
            for name, value in d.counters().items():
                out[name] += value
    return out


class Ground:
    """Sends telecommand packets through FOP-1 as CLTUs on every link and decodes telemetry.

    ``corrupt(link_index, cltu) -> cltu`` lets tests and the demo damage what one link carries.
    ``packets`` holds the TM packets decoded, ``channel_packets`` the same as (VC ID, packet).
    With ``security`` (an ``obsw.frames.sdls.TcSecurity``) each segment is signed with its
    channel's SA before FOP-1 (ApplySecurity in virtual channel generation), and ``state`` (a
    ``keys.StateFile``) saves the sequence numbers after each one. With ``tm_security`` (an
    ``obsw.frames.sdls_gcm.TmSecurity``) TM frames of secured VCs are verified and decrypted.

    With ``tm_decoder`` (a function returning an ``obsw.frames.tm_coding.TmDecoder``, e.g.
    ``LinkSettings.decoder`` of ``obsw_host.frames.coding``) each link's TM is channel decoded
    (Reed-Solomon, Viterbi, frame synchronization with bit errors and slips); a link whose
    ``soft`` is true gives soft symbols (``obsw_host.frames.radio``), the others octets.
    ``coding()`` sums the decoders' counters (frames, RS symbols corrected, channel symbols the
    Viterbi decoder corrected, uncorrectable codeblocks, locks, losses of lock, slips).
    """

    def __init__(
        self,
        links,
        scid,
        vcid=0,
        map_id=1,
        tm_frame_length=256,
        tc_randomize=False,
        tm_randomize=True,
        window=5,  # FOP-1's K: at most FARM-1's positive window (W/2 of the OBC's W=10)
        t1=2.0,
        transmission_limit=5,
        corrupt=None,
        security=None,
        state=None,
        tm_security=None,
        tm_decoder=None,
    ):
        self.links = list(links)
        self.scid = scid
        self.vcid = vcid
        self.security = security
        self.state = state
        self.map_id = map_id
        self.tc_randomize = tc_randomize
        self.fop = F.Fop1(scid, vcid, window, t1, transmission_limit)
        self.corrupt = corrupt
        if tm_decoder is None:
            self.decoders = [CaduDecoder(tm_frame_length, tm_randomize) for _ in self.links]
        else:
            self.decoders = [CodedInput(tm_decoder(), getattr(link, "soft", False))
                             for link in self.links]  # fmt: skip
        self.dedup = Deduplicator(5.0, depth=4096)  # one link may lag by a burst
        self.demux = TmDemultiplexer(scid, security=tm_security)
        self.queue = deque()
        self.notifications = []
        self.packets = deque()
        self.channel_packets = deque()
        self.sent_frames = []
        self.bad_frames = 0
        self._last_mc = None

    def initiate(self, now, kind=F.INITIATE_AD_WITH_UNLOCK, qualifier=None):
        rid = self.fop.directive(kind, qualifier, now)
        self._flush(now)
        return rid

    def send(self, packet, now, map_id=None, bypass=False):
        """Queue a packet; AD service unless ``bypass`` (sent at once with the BD service)."""
        seg = Segment(self.map_id if map_id is None else map_id, packet).pack()
        if self.security is not None:
            seg = self.security.apply(self.scid, self.vcid, seg, bypass)
            if self.state is not None:
                self.state.save()
        if bypass:
            self.fop.send_bd(seg, now)
        else:
            self.queue.append(seg)
        self._flush(now)

    def _flush(self, now):
        while self.queue and self.fop.ready:
            self.fop.send_ad(self.queue.popleft(), now)
        for frame in self.fop.take_frames():
            self.sent_frames.append(frame)
            cltu = encode(frame.pack(), self.tc_randomize)
            for i, link in enumerate(self.links):
                link.write(self.corrupt(i, cltu) if self.corrupt else cltu)
        self.notifications.extend(self.fop.take_notifications())

    def poll(self, now, timeout=0.05):
        """Read the links, decode telemetry, feed CLCWs to FOP-1; returns new TM packets."""
        readable, _, _ = select.select(self.links, [], [], timeout)
        got = []
        for i, link in enumerate(self.links):
            if link not in readable:
                continue
            for raw in self.decoders[i].feed(link.read()):
                if self.dedup.duplicate(raw, i, now):
                    continue
                try:
                    frame = TmFrame.unpack(raw)
                    packets = self.demux.on_frame(frame)
                except FrameError:
                    self.bad_frames += 1
                    continue
                got.extend(packets)
                for p in packets:
                    self.channel_packets.append((frame.vcid, p))
                if frame.ocf is not None and self.demux.clcw is not None:
                    self.fop.on_clcw(self.demux.clcw, now)
        self.fop.tick(now)
        self._flush(now)
        self.packets.extend(got)
        return got

    def coding(self):
        """The channel decoders' counters summed over the links (zeros without coding)."""
        return coding_counters(self.decoders)

    @property
    def idle(self):
        """Nothing queued and every AD frame acknowledged."""
        return not self.queue and self.fop.outstanding == 0
