"""CCSDS Space Packet Protocol (133.0-B-2): headers, packets, counts, idle packets, streams."""

from obsw.compat import Struct, const
from obsw.errors import too_short

PACKET_VERSION = const(0)  # the only packet version number 133.0-B-2 defines ('000')
TYPE_TM = const(0)
TYPE_TC = const(1)
SEQ_CONTINUATION = const(0)
SEQ_FIRST = const(1)
SEQ_LAST = const(2)
SEQ_UNSEGMENTED = const(3)
APID_IDLE = const(0x7FF)
APID_MAX = const(0x7FF)
SEQ_COUNT_MODULO = const(0x4000)
HEADER_SIZE = const(6)
MAX_PACKET_SIZE = const(65542)  # 6-octet header + up to 65536 octets of packet data field

_HDR_FMT = ">HHH"


_HEADER = Struct(_HDR_FMT)


class SppError(ValueError):
    """Base of every space packet decode and encode error."""


class BytesTooShortError(SppError):
    """Fewer octets than a header or a packet needs (``obsw.errors``: the too-short kind)."""

    def __init__(self, what, needed, got):
        super().__init__(too_short(what, needed, got))
        self.what = what
        self.needed = needed
        self.got = got


class PacketVersionError(SppError):
    """A packet version number other than 0 ('000')."""

    def __init__(self, version):
        super().__init__("packet version number %d, expected %d" % (version, PACKET_VERSION))
        self.version = version


class FieldRangeError(SppError):
    """A header field value that does not fit its field (raised when packing)."""

    def __init__(self, field, value, maximum):
        super().__init__("%s %r out of range 0..%d" % (field, value, maximum))
        self.field = field
        self.value = value
        self.maximum = maximum


def check_range(field, value, maximum):
    """Raise FieldRangeError unless ``0 <= value <= maximum`` (``value`` an int)."""
    if not isinstance(value, int) or value < 0 or value > maximum:
        raise FieldRangeError(field, value, maximum)
    return value


def packet_id(packet_type, sec_header_flag, apid, version=PACKET_VERSION):
    """The 16-bit packet identification word including the version number, as sent."""
    return (version << 13) | (packet_type << 12) | ((1 if sec_header_flag else 0) << 11) | apid


def sequence_control(seq_flags, seq_count):
    """The 16-bit packet sequence control word."""
    return (seq_flags << 14) | seq_count


class PrimaryHeader:
    """The six-octet primary header; ``data_length`` is the field value (data octets - 1)."""

    __slots__ = (
        "version",
        "packet_type",
        "sec_header_flag",
        "apid",
        "seq_flags",
        "seq_count",
        "data_length",
    )

    def __init__(
        self,
        packet_type=TYPE_TM,
        sec_header_flag=False,
        apid=0,
        seq_flags=SEQ_UNSEGMENTED,
        seq_count=0,
        data_length=0,
        version=PACKET_VERSION,
    ):
        self.version = version
        self.packet_type = packet_type
        self.sec_header_flag = bool(sec_header_flag)
        self.apid = apid
        self.seq_flags = seq_flags
        self.seq_count = seq_count  # the packet sequence count or, for some TCs, packet name
        self.data_length = data_length

    @property
    def packet_id(self):
        return packet_id(self.packet_type, self.sec_header_flag, self.apid, self.version)

    @property
    def sequence_control(self):
        return sequence_control(self.seq_flags, self.seq_count)

    @property
    def packet_length(self):
        """Whole packet length in octets (header included)."""
        return self.data_length + 7

    def pack(self):
        check_range("packet version", self.version, 7)
        check_range("packet type", self.packet_type, 1)
        check_range("APID", self.apid, APID_MAX)
        check_range("sequence flags", self.seq_flags, 3)
        check_range("sequence count", self.seq_count, SEQ_COUNT_MODULO - 1)
        check_range("packet data length", self.data_length, 0xFFFF)
        return _HEADER.pack(self.packet_id, self.sequence_control, self.data_length)

    @classmethod
    def unpack(cls, buf, offset=0):
        """Decode the header at ``offset``; any version number is accepted here."""
        n = len(buf) - offset
        if n < HEADER_SIZE:
            raise BytesTooShortError("space packet primary header", HEADER_SIZE, n)
        pid, psc, dlen = _HEADER.unpack_from(buf, offset)
        return cls(
            (pid >> 12) & 1,
            (pid >> 11) & 1 == 1,
            pid & 0x7FF,
            psc >> 14,
            psc & 0x3FFF,
            dlen,
            pid >> 13,
        )

    def __eq__(self, other):
        return isinstance(other, PrimaryHeader) and _fields(self) == _fields(other)

    def __repr__(self):
        return "PrimaryHeader(%s)" % ", ".join(
            "%s=%r" % (k, getattr(self, k)) for k in PrimaryHeader.__slots__
        )


def _fields(obj):
    return tuple(getattr(obj, k) for k in obj.__slots__)


class SpacePacket:
    """A space packet: primary header fields and the packet data field as bytes."""

    __slots__ = ("packet_type", "sec_header_flag", "apid", "seq_flags", "seq_count", "data")

    def __init__(
        self,
        packet_type,
        apid,
        data,
        sec_header_flag=False,
        seq_flags=SEQ_UNSEGMENTED,
        seq_count=0,
    ):
        self.packet_type = packet_type
        self.apid = apid
        self.data = data
        self.sec_header_flag = bool(sec_header_flag)
        self.seq_flags = seq_flags
        self.seq_count = seq_count

    @property
    def version(self):
        return PACKET_VERSION

    @property
    def data_length(self):
        return len(self.data) - 1

    @property
    def packet_id(self):
        return packet_id(self.packet_type, self.sec_header_flag, self.apid)

    @property
    def sequence_control(self):
        return sequence_control(self.seq_flags, self.seq_count)

    @property
    def is_idle(self):
        return self.apid == APID_IDLE

    def header(self):
        return PrimaryHeader(
            self.packet_type,
            self.sec_header_flag,
            self.apid,
            self.seq_flags,
            self.seq_count,
            len(self.data) - 1,
        )

    def __len__(self):
        return HEADER_SIZE + len(self.data)

    def pack(self):
        n = len(self.data)
        if n < 1 or n > 65536:
            raise FieldRangeError("packet data field length", n, 65536)
        check_range("packet type", self.packet_type, 1)
        check_range("APID", self.apid, APID_MAX)
        check_range("sequence flags", self.seq_flags, 3)
        check_range("sequence count", self.seq_count, SEQ_COUNT_MODULO - 1)
        return _HEADER.pack(self.packet_id, self.sequence_control, n - 1) + bytes(self.data)

    @classmethod
    def unpack_from(cls, buf, offset=0):
        """Decode the packet starting at ``offset``; returns ``(packet, end_offset)``."""
        n = len(buf) - offset
        if n < HEADER_SIZE:
            raise BytesTooShortError("space packet primary header", HEADER_SIZE, n)
        pid, psc, dlen = _HEADER.unpack_from(buf, offset)
        if pid >> 13:
            raise PacketVersionError(pid >> 13)
        end = offset + dlen + 7
        if end > len(buf):
            raise BytesTooShortError("space packet", dlen + 7, n)
        pkt = cls(
            (pid >> 12) & 1,
            pid & 0x7FF,
            bytes(buf[offset + HEADER_SIZE : end]),
            (pid >> 11) & 1,
            psc >> 14,
            psc & 0x3FFF,
        )
        return pkt, end

    @classmethod
    def unpack(cls, buf):
        """Decode the packet at the start of ``buf`` (bytes after it are left alone)."""
        return cls.unpack_from(buf, 0)[0]

    def __eq__(self, other):
        return isinstance(other, SpacePacket) and _fields(self) == _fields(other)

    def __repr__(self):
        return "SpacePacket(type=%d, apid=%d, flags=%d, count=%d, sec=%d, data=%d bytes)" % (
            self.packet_type,
            self.apid,
            self.seq_flags,
            self.seq_count,
            self.sec_header_flag,
            len(self.data),
        )


def idle_packet(length, seq_count=0, pattern=b"\xff"):
    """An idle packet (APID all ones) of ``length`` octets in total, filled with ``pattern``."""
    n = length - HEADER_SIZE
    if n < 1 or n > 65536:
        raise FieldRangeError("idle packet data field length", n, 65536)
    if not pattern:
        raise ValueError("idle data pattern must not be empty")
    fill = (bytes(pattern) * (n // len(pattern) + 1))[:n]
    return SpacePacket(TYPE_TM, APID_IDLE, fill, False, SEQ_UNSEGMENTED, seq_count)


class SequenceCounter:
    """Per-APID 14-bit source sequence counts for packets being sent; they wrap to 0."""

    def __init__(self, start=0):
        self._start = start & 0x3FFF
        self._counts = {}

    def next(self, apid):
        """The count for the next packet of ``apid``, advancing the counter."""
        c = self._counts.get(apid, self._start)
        self._counts[apid] = (c + 1) & 0x3FFF
        return c

    def peek(self, apid):
        return self._counts.get(apid, self._start)

    def counts(self):
        """{apid: the count of its next packet} of every APID that sent one."""
        return dict(self._counts)

    def set(self, apid, value):
        self._counts[apid] = check_range("sequence count", value, SEQ_COUNT_MODULO - 1)

    def reset(self, apid=None):
        if apid is None:
            self._counts.clear()
        else:
            self._counts.pop(apid, None)


class SequenceMonitor:
    """Per-APID check of received counts: how many packets went missing before each one."""

    def __init__(self):
        self._expected = {}
        self.lost = 0

    def observe(self, apid, count):
        """Return the packets missing before this one (0 in order, None for an APID's first)."""
        exp = self._expected.get(apid)
        self._expected[apid] = (count + 1) & 0x3FFF
        if exp is None:
            return None
        gap = (count - exp) & 0x3FFF
        self.lost += gap
        return gap


# why a stream parser dropped bytes
SKIP_VERSION = "version"
SKIP_APID = "apid"
SKIP_LENGTH = "length"
SKIP_INVALID = "invalid"
SKIP_TRUNCATED = "truncated"


class PacketStream:
    """Cut a byte stream into whole space packets, resynchronising on garbage.

    ``feed(data)`` returns ``(packets, skipped)``: the complete packets (bytes) found so far and
    how many octets were dropped while looking for a plausible header. A header is plausible
    when its version is 0, its APID is in ``apids`` (if given), its total length lies within
    ``min_length..max_length`` and, once the packet is complete, ``validate(packet)`` (if
    given, e.g. a CRC check) returns true. On a failed check one octet is dropped and the
    search goes on from the next. ``flush()`` ends the stream: an incomplete packet at the
    head is given up octet by octet so any whole packet behind it is still found.
    """

    def __init__(self, max_length=MAX_PACKET_SIZE, apids=None, min_length=7, validate=None):
        self.max_length = max_length
        self.min_length = min_length
        self.apids = apids
        self.validate = validate
        self._buf = bytearray()
        self.packets = 0
        self.skipped = 0  # octets dropped since the stream started
        self.reasons = {}  # reason -> octets dropped for it

    @property
    def pending(self):
        """Octets held back waiting for the rest of a packet."""
        return len(self._buf)

    def _skip(self, reason, n=1):
        self.reasons[reason] = self.reasons.get(reason, 0) + n

    def feed(self, data):
        if data:
            self._buf.extend(data)
        return self._scan(False)

    def flush(self):
        return self._scan(True)

    def _scan(self, final):
        buf = self._buf
        out = []
        pos = 0
        skipped = 0
        size = len(buf)
        apids = self.apids
        while size - pos >= HEADER_SIZE:
            pid, _, dlen = _HEADER.unpack_from(buf, pos)
            total = dlen + 7
            if pid >> 13:
                reason = SKIP_VERSION
            elif apids is not None and (pid & 0x7FF) not in apids:
                reason = SKIP_APID
            elif total > self.max_length or total < self.min_length:
                reason = SKIP_LENGTH
            elif pos + total > size:
                if not final:
                    break
                reason = SKIP_TRUNCATED
            else:
                pkt = bytes(buf[pos : pos + total])
                if self.validate is None or self.validate(pkt):
                    out.append(pkt)
                    pos += total
                    continue
                reason = SKIP_INVALID
            self._skip(reason)
            pos += 1
            skipped += 1
        if final and pos < size:
            # fewer octets than a header: nothing more can come of them
            self._skip(SKIP_TRUNCATED, size - pos)
            skipped += size - pos
            pos = size
        if pos:
            self._buf = buf[pos:]  # MicroPython's bytearray has no slice deletion
        self.skipped += skipped
        self.packets += len(out)
        return out, skipped
