"""TM transfer frames (CCSDS 132.0-B): primary header, secondary header, OCF, FECF."""

from obsw.compat import const
from obsw.crc import crc16_ccitt
from obsw.frames.errors import FecfError, FrameHeaderError, FrameLengthError, FrameTooShortError

FHP_NO_PACKET = const(0x7FF)  # no packet starts in this frame
FHP_IDLE = const(0x7FE)  # the frame holds only idle data
HEADER_LENGTH = const(6)
MAX_FRAME_LENGTH = const(2048)


class TmFrame:
    """A TM transfer frame. ``ocf`` is 4 bytes (a CLCW) or None; lengths come from the bytes."""

    def __init__(
        self,
        scid,
        vcid,
        data,
        mc_count=0,
        vc_count=0,
        fhp=0,
        ocf=None,
        secondary_header=None,
        sync=False,
        packet_order=False,
        segment_length_id=3,
    ):
        self.scid = scid
        self.vcid = vcid
        self.data = bytes(data)
        self.mc_count = mc_count
        self.vc_count = vc_count
        self.fhp = fhp
        self.ocf = None if ocf is None else bytes(ocf)
        self.secondary_header = None if secondary_header is None else bytes(secondary_header)
        self.sync = bool(sync)
        self.packet_order = bool(packet_order)
        self.segment_length_id = segment_length_id

    def length(self, fecf=True):
        n = HEADER_LENGTH + len(self.data)
        if self.secondary_header is not None:
            n += 1 + len(self.secondary_header)
        if self.ocf is not None:
            n += 4
        return n + (2 if fecf else 0)

    def pack(self, fecf=True):
        n = self.length(fecf)
        if n > MAX_FRAME_LENGTH:
            raise FrameLengthError("TM frame", MAX_FRAME_LENGTH, n)
        if not 0 <= self.scid < 1024 or not 0 <= self.vcid < 8 or not 0 <= self.fhp < 2048:
            raise ValueError("TM frame SCID, VCID or first header pointer out of range")
        if self.ocf is not None and len(self.ocf) != 4:
            raise FrameLengthError("operational control field", 4, len(self.ocf))
        sh = self.secondary_header
        if sh is not None and not 1 <= len(sh) <= 63:
            raise FrameLengthError("TM secondary header data", 63, len(sh))
        out = bytearray(n)
        out[0] = self.scid >> 4
        out[1] = (self.scid & 0x0F) << 4 | self.vcid << 1 | (1 if self.ocf is not None else 0)
        out[2] = self.mc_count & 0xFF
        out[3] = self.vc_count & 0xFF
        out[4] = (
            (0x80 if sh is not None else 0)
            | (0x40 if self.sync else 0)
            | (0x20 if self.packet_order else 0)
            | (self.segment_length_id & 3) << 3
            | self.fhp >> 8
        )
        out[5] = self.fhp & 0xFF
        i = HEADER_LENGTH
        if sh is not None:
            out[i] = len(sh)  # version 00, length = whole secondary header minus one
            out[i + 1 : i + 1 + len(sh)] = sh
            i += 1 + len(sh)
        out[i : i + len(self.data)] = self.data
        i += len(self.data)
        if self.ocf is not None:
            out[i : i + 4] = self.ocf
        if fecf:
            c = crc16_ccitt(memoryview(out)[: n - 2])
            out[n - 2] = c >> 8
            out[n - 1] = c & 0xFF
        return bytes(out)

    @classmethod
    def unpack(cls, buf, fecf=True):
        """Decode a whole frame; the frame length is ``len(buf)`` (fixed per physical channel)."""
        n = len(buf)
        tail = 2 if fecf else 0
        if n < HEADER_LENGTH + tail:
            raise FrameTooShortError("TM frame", HEADER_LENGTH + tail, n)
        if buf[0] >> 6:
            raise FrameHeaderError("TM frame version", buf[0] >> 6, "0")
        if fecf:
            received = (buf[n - 2] << 8) | buf[n - 1]
            computed = crc16_ccitt(memoryview(buf)[: n - 2])
            if received != computed:
                raise FecfError(received, computed)
        end = n - tail
        i = HEADER_LENGTH
        sh = None
        if buf[4] & 0x80:
            if n - tail < i + 1:
                raise FrameTooShortError("TM frame", i + 1 + tail, n)
            if buf[i] >> 6:
                raise FrameHeaderError("TM secondary header version", buf[i] >> 6, "0")
            k = buf[i] & 0x3F
            if k == 0 or i + 1 + k > end:
                raise FrameLengthError("TM secondary header", end - i - 1, k)
            sh = bytes(buf[i + 1 : i + 1 + k])
            i += 1 + k
        ocf = None
        if buf[1] & 1:
            if end - 4 < i:
                raise FrameTooShortError("TM frame", i + 4 + tail, n)
            ocf = bytes(buf[end - 4 : end])
            end -= 4
        return cls(
            (buf[0] & 0x3F) << 4 | buf[1] >> 4,
            (buf[1] >> 1) & 7,
            bytes(buf[i:end]),
            buf[2],
            buf[3],
            (buf[4] & 7) << 8 | buf[5],
            ocf,
            sh,
            buf[4] & 0x40,
            buf[4] & 0x20,
            (buf[4] >> 3) & 3,
        )

    def __eq__(self, other):
        return isinstance(other, TmFrame) and self.pack(False) == other.pack(False)

    def __repr__(self):
        return "TmFrame(scid=%d vc=%d mc=%d vcc=%d fhp=0x%X len=%d%s)" % (
            self.scid,
            self.vcid,
            self.mc_count,
            self.vc_count,
            self.fhp,
            len(self.data),
            " ocf" if self.ocf is not None else "",
        )
