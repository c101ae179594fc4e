"""TC transfer frames (CCSDS 232.0-B): primary header, frame error control, control commands."""

from obsw.compat import const
from obsw.crc import crc16_ccitt
from obsw.frames.errors import (
    ControlCommandError,
    FecfError,
    FrameHeaderError,
    FrameLengthError,
    FrameTooShortError,
)

TYPE_AD = const(0)  # sequence-controlled data (COP-1)
TYPE_BD = const(2)  # expedited data (bypass)
TYPE_BC = const(3)  # expedited control command (bypass + control)
TYPE_AC = const(1)  # not allowed by the standard
TYPE_NAMES = ("AD", "AC", "BD", "BC")

MAX_FRAME_LENGTH = const(1024)
HEADER_LENGTH = const(5)

CMD_UNLOCK = const(1)
CMD_SET_VR = const(2)
UNLOCK = b"\x00"


def set_vr_command(vr):
    """The Set V(R) control command: 0x82 0x00 V(R)."""
    return bytes((0x82, 0x00, vr & 0xFF))


def parse_control_command(data):
    """Return (CMD_UNLOCK, None) or (CMD_SET_VR, value); raise ControlCommandError otherwise."""
    if len(data) == 1 and data[0] == 0x00:
        return CMD_UNLOCK, None
    if len(data) == 3 and data[0] == 0x82 and data[1] == 0x00:
        return CMD_SET_VR, data[2]
    raise ControlCommandError(data)


def frame_length(buf):
    """Total length of the TC frame starting at buf[0], from its frame length field."""
    if len(buf) < HEADER_LENGTH:
        raise FrameTooShortError("TC frame", HEADER_LENGTH, len(buf))
    return (((buf[2] & 0x03) << 8) | buf[3]) + 1


class TcFrame:
    """A TC transfer frame; ``data`` is the whole frame data field (segment header included)."""

    def __init__(self, scid, vcid, data, seq=0, bypass=False, control=False, fecf=True):
        self.scid = scid
        self.vcid = vcid
        self.data = bytes(data)
        self.seq = seq
        self.bypass = bool(bypass)
        self.control = bool(control)
        self.fecf = fecf

    @property
    def frame_type(self):
        return (2 if self.bypass else 0) | (1 if self.control else 0)

    @property
    def type_name(self):
        return TYPE_NAMES[self.frame_type]

    def __len__(self):
        return HEADER_LENGTH + len(self.data) + (2 if self.fecf else 0)

    def __eq__(self, other):
        return isinstance(other, TcFrame) and self.pack() == other.pack()

    def __repr__(self):
        return "TcFrame(%s scid=%d vcid=%d seq=%d len=%d)" % (
            self.type_name,
            self.scid,
            self.vcid,
            self.seq,
            len(self.data),
        )

    def pack(self):
        n = len(self)
        if n > MAX_FRAME_LENGTH:
            raise FrameLengthError("TC frame", MAX_FRAME_LENGTH, n)
        if not 0 <= self.scid < 1024 or not 0 <= self.vcid < 64 or not 0 <= self.seq < 256:
            raise ValueError("TC frame SCID, VCID or sequence number out of range")
        out = bytearray(n)
        out[0] = (0x20 if self.bypass else 0) | (0x10 if self.control else 0) | (self.scid >> 8)
        out[1] = self.scid & 0xFF
        out[2] = (self.vcid << 2) | ((n - 1) >> 8)
        out[3] = (n - 1) & 0xFF
        out[4] = self.seq
        out[5 : 5 + len(self.data)] = self.data
        if self.fecf:
            c = crc16_ccitt(memoryview(out)[: n - 2])
            out[n - 2] = c >> 8
            out[n - 1] = c & 0xFF
        return bytes(out)

    @classmethod
    def unpack(cls, buf, fecf=True, trailing=False):
        """Decode one frame; with ``trailing`` bytes after the frame (CLTU fill) are ignored."""
        n = frame_length(buf)
        if len(buf) < n:
            raise FrameTooShortError("TC frame", n, len(buf))
        if len(buf) > n and not trailing:
            raise FrameLengthError("TC frame", n, len(buf))
        if buf[0] >> 6:
            raise FrameHeaderError("TC frame version", buf[0] >> 6, "0")
        tail = 2 if fecf else 0
        if n < HEADER_LENGTH + tail:
            raise FrameTooShortError("TC frame", HEADER_LENGTH + tail, n)
        if fecf:
            received = (buf[n - 2] << 8) | buf[n - 1]
            computed = crc16_ccitt(memoryview(buf)[: n - 2])
            if received != computed:
                raise FecfError(received, computed)
        return cls(
            ((buf[0] & 0x03) << 8) | buf[1],
            buf[2] >> 2,
            bytes(buf[HEADER_LENGTH : n - tail]),
            buf[4],
            buf[0] & 0x20,
            buf[0] & 0x10,
            fecf,
        )


# Segment header (232.0-B 4.1.3): sequence flags and MAP ID in one octet.
SEG_CONTINUING = const(0)
SEG_FIRST = const(1)
SEG_LAST = const(2)
SEG_UNSEGMENTED = const(3)


class Segment:
    """A TC segment: the frame data field when the virtual channel uses segment headers."""

    def __init__(self, map_id, data, flags=SEG_UNSEGMENTED):
        self.map_id = map_id
        self.data = bytes(data)
        self.flags = flags

    def pack(self):
        if not 0 <= self.map_id < 64:
            raise ValueError("MAP ID %d out of range 0..63" % self.map_id)
        return bytes(((self.flags << 6) | self.map_id,)) + self.data

    @classmethod
    def unpack(cls, buf):
        if len(buf) < 1:
            raise FrameTooShortError("TC segment", 1, len(buf))
        return cls(buf[0] & 0x3F, bytes(buf[1:]), buf[0] >> 6)

    def __repr__(self):
        return "Segment(map=%d flags=%d len=%d)" % (self.map_id, self.flags, len(self.data))


def segment(data, map_id, max_data):
    """Split one packet into segments whose data fields hold at most ``max_data`` bytes."""
    if max_data < 1:
        raise ValueError("segment data size must be positive")
    if len(data) <= max_data:
        return [Segment(map_id, data, SEG_UNSEGMENTED)]
    out = []
    for i in range(0, len(data), max_data):
        if i == 0:
            flags = SEG_FIRST
        elif i + max_data >= len(data):
            flags = SEG_LAST
        else:
            flags = SEG_CONTINUING
        out.append(Segment(map_id, data[i : i + max_data], flags))
    return out


class Reassembler:
    """Rebuild MAP service data units from segments, one partial unit per MAP ID.

    ``push(seg)`` returns the complete unit or None. Out-of-order segments are dropped and
    counted in ``dropped`` (a first segment always restarts its MAP).
    """

    def __init__(self, max_length=65542):
        self.max_length = max_length
        self._partial = {}
        self.dropped = 0

    def push(self, seg):
        m = seg.map_id
        if seg.flags == SEG_UNSEGMENTED:
            if m in self._partial:
                self.dropped += 1
                del self._partial[m]
            return seg.data
        if seg.flags == SEG_FIRST:
            if m in self._partial:
                self.dropped += 1
            self._partial[m] = bytearray(seg.data)
            return None
        part = self._partial.get(m)
        if part is None:
            self.dropped += 1
            return None
        part.extend(seg.data)
        if len(part) > self.max_length:
            self.dropped += 1
            del self._partial[m]
            return None
        if seg.flags == SEG_LAST:
            del self._partial[m]
            return bytes(part)
        return None
