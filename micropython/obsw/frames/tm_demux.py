"""TM frames back into packets: per-channel extraction with spanning, gaps and idle data."""

from obsw.compat import const
from obsw.frames.clcw import Clcw
from obsw.frames.errors import FrameHeaderError
from obsw.frames.tm import FHP_IDLE, FHP_NO_PACKET, TmFrame
from obsw.spp import APID_IDLE

_HDR = const(6)


class PacketExtractor:
    """Rebuilds packets of one virtual channel; a gap in the VC frame count drops the partial
    packet (counted in ``lost``) and resynchronizes on the next first header pointer."""

    def __init__(self, keep_idle=False):
        self.keep_idle = keep_idle
        self._part = None  # bytes of a packet started in an earlier frame
        self._expect = None  # next VC frame count
        self.lost = 0
        self.gaps = 0

    def feed(self, frame):
        out = []
        fhp = frame.fhp
        if fhp == FHP_IDLE:
            self._expect = (frame.vc_count + 1) & 0xFF
            return out
        if self._expect is not None and frame.vc_count != self._expect:
            self.gaps += 1
            if self._part is not None:
                self.lost += 1
                self._part = None
        self._expect = (frame.vc_count + 1) & 0xFF
        data = frame.data
        if fhp == FHP_NO_PACKET:
            part = self._part
            if part is not None:
                part += data
                self._part = part
                if len(part) >= _HDR:
                    size = ((part[4] << 8) | part[5]) + 7
                    if len(part) >= size:
                        # It ended with this frame (the next one's pointer will be 0).
                        self._part = None
                        self._finish(part, out)
            return out
        if fhp > len(data):
            self._part = None
            self.lost += 1
            return out
        if self._part is not None:
            self._finish(self._part + data[:fhp], out)
            self._part = None
        i = fhp
        n = len(data)
        while i < n:
            if n - i < _HDR:
                self._part = data[i:]
                break
            size = ((data[i + 4] << 8) | data[i + 5]) + 7
            if i + size > n:
                self._part = data[i:]
                break
            self._emit(data[i : i + size], out)
            i += size
        return out

    def _finish(self, buf, out):
        # The bytes before the first header pointer must complete the spanning packet exactly.
        if len(buf) >= _HDR and ((buf[4] << 8) | buf[5]) + 7 == len(buf):
            self._emit(buf, out)
        else:
            self.lost += 1

    def _emit(self, packet, out):
        if not self.keep_idle and ((packet[0] & 7) << 8 | packet[1]) == APID_IDLE:
            return
        out.append(bytes(packet))


class TmDemultiplexer:
    """Checks TM frames of one master channel and extracts the packets of every channel.

    ``feed(frame_bytes)`` returns the list of packets (raises FrameError on a bad frame);
    ``clcw`` holds the last CLCW seen in an OCF; ``mc_gaps`` counts master channel count gaps.
    With ``security`` (an ``obsw.frames.sdls_gcm.TmSecurity``) the frames of VCs with an SA are
    verified and decrypted first; a frame that fails is dropped whole, its CLCW too, and
    counted in ``security.counters``.
    """

    def __init__(self, scid, fecf=True, security=None):
        self.scid = scid
        self.fecf = fecf
        self.security = security
        self.channels = {}
        self.clcw = None
        self.frames = 0
        self.mc_gaps = 0
        self._mc = None

    def feed(self, buf):
        frame = TmFrame.unpack(buf, self.fecf)
        return self.on_frame(frame)

    def on_frame(self, frame):
        if frame.scid != self.scid:
            raise FrameHeaderError("TM frame SCID", frame.scid, str(self.scid))
        if frame.segment_length_id != 3 or frame.sync:
            raise FrameHeaderError("TM data field status", frame.segment_length_id, "packets")
        if self._mc is not None and frame.mc_count != self._mc:
            self.mc_gaps += 1
        self._mc = (frame.mc_count + 1) & 0xFF
        self.frames += 1
        if self.security is not None:
            outcome, clear = self.security.open(frame.vcid, frame.data)
            if clear is None:
                return []
            frame.data = clear
        if frame.ocf is not None and not frame.ocf[0] & 0x80:
            self.clcw = Clcw.unpack(frame.ocf)
        ch = self.channels.get(frame.vcid)
        if ch is None:
            ch = self.channels[frame.vcid] = PacketExtractor()
        return ch.feed(frame)
