"""What PUS-C TC and TM packets share: the ``PusPacket`` base (primary header fields, framing,
length and PEC checks, refused fields), PUS version, errors, request IDs."""

from obsw.compat import Struct, const
from obsw.crc import crc16_ccitt
from obsw.crc import crc16_ccitt_update as _crc
from obsw.errors import too_short, wrong_length
from obsw.pus.config import DEFAULT
from obsw.spp import SEQ_UNSEGMENTED, TYPE_TC, FieldRangeError, SppError

PUS_VERSION = const(2)  # TC and TM packet PUS version number of PUS-C

# acknowledgement flags of a TC secondary header: which successful steps to report
ACK_NONE = const(0)
ACK_ACCEPTANCE = const(1)
ACK_START = const(2)
ACK_PROGRESS = const(4)
ACK_COMPLETION = const(8)
ACK_ALL = const(15)

_HDR = Struct(">HHH")
_PEC = Struct(">H")
_PEC_PACK = _PEC.pack
_WORDS = Struct(">HH")


class PusError(SppError):
    """A PUS packet that cannot be accepted.

    ``packet_id`` and ``sequence_control`` are the primary header words when they were
    readable (None otherwise), so a failed acceptance report can still name the request.
    """

    def __init__(self, msg, packet_id=None, sequence_control=None):
        super().__init__(msg)
        self.packet_id = packet_id
        self.sequence_control = sequence_control

    @property
    def apid(self):
        return None if self.packet_id is None else self.packet_id & 0x7FF

    def request_id(self):
        """The RequestId of the offending packet, or None if its header was not readable."""
        if self.packet_id is None:
            return None
        return RequestId.from_words(self.packet_id, self.sequence_control)


class PusLengthError(PusError):
    """A packet whose length is not what ``what`` must be: ``expected`` and ``got`` octets
    (``obsw.errors``: the length kind; ``message`` says more than the default)."""

    def __init__(self, what, expected, got, packet_id=None, sequence_control=None, message=None):
        super().__init__(message or wrong_length(what, expected, got), packet_id, sequence_control)
        self.what = what
        self.expected = expected
        self.got = got


class PusTooShortError(PusLengthError):
    """Fewer octets than ``what`` needs (``obsw.errors``: the too-short kind)."""

    def __init__(self, what, needed, got, packet_id=None, sequence_control=None):
        message = too_short(what, needed, got)
        super().__init__(what, needed, got, packet_id, sequence_control, message)
        self.needed = needed


class PusCrcError(PusError):
    """Packet error control mismatch: ``expected`` as computed, ``actual`` as received."""

    def __init__(self, what, expected, actual, packet_id, sequence_control):
        super().__init__(
            "%s packet error control 0x%04x, computed 0x%04x" % (what, actual, expected),
            packet_id,
            sequence_control,
        )
        self.expected = expected
        self.actual = actual


class PusVersionError(PusError):
    """A TC or TM packet PUS version number other than 2 (PUS-C)."""

    def __init__(self, what, version, packet_id, sequence_control):
        super().__init__(
            "%s packet PUS version %d, expected %d" % (what, version, PUS_VERSION),
            packet_id,
            sequence_control,
        )
        self.version = version


class PusHeaderError(PusError):
    """A header field value this decoder cannot take (``field``, ``expected``, ``actual``)."""

    def __init__(self, what, field, expected, actual, packet_id=None, sequence_control=None):
        super().__init__(
            "%s %s %s, expected %s" % (what, field, actual, expected),
            packet_id,
            sequence_control,
        )
        self.field = field
        self.expected = expected
        self.actual = actual


class RequestId:
    """The request identifier service 1 reports carry: a TC's first two header words."""

    __slots__ = ("packet_id", "sequence_control")

    def __init__(self, apid, seq_count, seq_flags=SEQ_UNSEGMENTED, packet_type=TYPE_TC, sec=1):
        self.packet_id = (packet_type << 12) | ((1 if sec else 0) << 11) | apid
        self.sequence_control = (seq_flags << 14) | seq_count

    @classmethod
    def from_words(cls, packet_id, sequence_control):
        r = object.__new__(cls)
        r.packet_id = packet_id
        r.sequence_control = sequence_control
        return r

    version = property(lambda self: self.packet_id >> 13)
    packet_type = property(lambda self: (self.packet_id >> 12) & 1)
    sec_header_flag = property(lambda self: (self.packet_id >> 11) & 1)
    apid = property(lambda self: self.packet_id & 0x7FF)
    seq_flags = property(lambda self: self.sequence_control >> 14)
    seq_count = property(lambda self: self.sequence_control & 0x3FFF)

    def pack(self):
        return _WORDS.pack(self.packet_id, self.sequence_control)

    @classmethod
    def unpack(cls, buf, offset=0):
        if len(buf) - offset < 4:
            raise PusTooShortError("request ID", 4, len(buf) - offset)
        return cls.from_words(*_WORDS.unpack_from(buf, offset))

    def __eq__(self, other):
        return (
            isinstance(other, RequestId)
            and self.packet_id == other.packet_id
            and self.sequence_control == other.sequence_control
        )

    def __hash__(self):
        return (self.packet_id << 16) | self.sequence_control

    def __repr__(self):
        return "RequestId(apid=%d, seq_count=%d, flags=%d, type=%d)" % (
            self.apid,
            self.seq_count,
            self.seq_flags,
            self.packet_type,
        )


def check_range(field, value, maximum):
    """FieldRangeError unless ``value`` is an integer in 0..``maximum``."""
    if not isinstance(value, int) or value < 0 or value > maximum:
        raise FieldRangeError(field, value, maximum)


class PusPacket:
    """What a PUS-C TC and TM have alike: the primary header's fields and words, framing and
    its checks, the PEC, and how a refused field is reported. ``PusTc`` and ``PusTm`` add
    their secondary headers; ``KIND`` is "TC" or "TM", ``ID`` the packet ID without the APID
    (version 0, the packet type, secondary header flag 1)."""

    __slots__ = ()
    KIND = ""
    ID = 0

    @property
    def packet_id(self):
        return self.ID | self.apid

    @property
    def sequence_control(self):
        return (self.seq_flags << 14) | self.seq_count

    @property
    def message_type(self):
        return (self.service, self.subtype)

    @classmethod
    def unpack_from(cls, buf, offset=0, config=DEFAULT):
        """Decode the packet at ``offset``; returns ``(packet, end_offset)``."""
        return cls._decode(buf, offset, config, False)

    def _check_primary(self):
        check_range("APID", self.apid, 0x7FF)
        check_range("sequence count", self.seq_count, 0x3FFF)
        check_range("sequence flags", self.seq_flags, 3)
        check_range("service type", self.service, 255)
        check_range("message subtype", self.subtype, 255)

    def _refused(self, config, total):
        """Why struct.pack refused this packet: FieldRangeError for an integer out of range,
        TypeError for a value that is no integer, or None (the caller then re-raises struct's
        own error)."""
        try:
            self._check(config, total)
        except FieldRangeError as e:
            if isinstance(e.value, int):
                return e
            return TypeError("%s must be an integer, not %r" % (e.field, e.value))
        except Exception:  # a malformed value the checks themselves trip over
            pass
        return None

    def _sealed(self, c, total, head):
        """The packed packet: ``head`` within the mission's size, then its PEC."""
        if total > c.max_packet_size:
            raise FieldRangeError(self.KIND + " packet length", total, c.max_packet_size)
        if c.pec:
            return head + _PEC_PACK(_crc(head, 0xFFFF))
        return head

    @classmethod
    def _frame(cls, buf, offset, config, exact, min_size):
        """Check everything up to the PEC; return (packet_id, seq_control, end, data_end)."""
        what = cls.KIND
        type_id = cls.ID
        n = len(buf) - offset
        if n < 6:
            raise PusTooShortError("%s packet primary header" % what, 6, n)
        pid, psc, dlen = _HDR.unpack_from(buf, offset)
        total = dlen + 7
        if pid & 0xF800 != type_id:
            if pid >> 13:
                raise PusHeaderError(what, "packet version number", 0, pid >> 13, pid, psc)
            if (pid ^ type_id) & 0x1000:
                raise PusHeaderError(
                    what, "packet type", type_id >> 12 & 1, pid >> 12 & 1, pid, psc
                )
            raise PusHeaderError(what, "secondary header flag", 1, 0, pid, psc)
        if total > n or (exact and total != n):
            says = "%s packet is %d bytes, packet data length field says %d" % (what, n, total)
            raise PusLengthError("%s packet" % what, total, n, pid, psc, says)
        if total < min_size:
            raise PusTooShortError(
                "%s packet (secondary header, PEC)" % what, min_size, total, pid, psc
            )
        if total > config.max_packet_size:
            most = "%s packet of %d bytes exceeds the mission maximum %d" % (
                what, total, config.max_packet_size)  # fmt: skip
            raise PusLengthError("%s packet" % what, config.max_packet_size, total, pid, psc, most)
        end = offset + total
        if config.pec:
            if crc16_ccitt(buf if exact else memoryview(buf)[offset:end]) != 0:
                got = _PEC.unpack_from(buf, end - 2)[0]
                computed = crc16_ccitt(memoryview(buf)[offset : end - 2])
                raise PusCrcError(what, computed, got, pid, psc)
            return pid, psc, end, end - 2
        return pid, psc, end, end


def read_int(buf, offset, size):
    """The big-endian unsigned integer of ``size`` octets at ``offset`` (0 for none)."""
    return int.from_bytes(bytes(buf[offset : offset + size]), "big") if size else 0


def failure_code(error):
    """The service 1 acceptance failure code (obsw.pus.messages) for a decode error."""
    if isinstance(error, PusCrcError):
        return 2  # FAILURE_INCORRECT_CHECKSUM
    if isinstance(error, PusLengthError):
        return 1  # FAILURE_INVALID_LENGTH
    if isinstance(error, (PusVersionError, PusHeaderError)):
        return 6  # FAILURE_UNSUPPORTED_HEADER
    return 5  # FAILURE_ILLEGAL_APP_DATA
