"""CFDP fixed PDU header (727.0-B-5 5.1) and the helpers every PDU codec shares."""

import struct

from obsw.cfdp.defs import (
    FILE_DIRECTIVE,
    TOWARD_RECEIVER,
    UNACKNOWLEDGED,
    VERSION,
    PduCrcError,
    PduFormatError,
    PduTooShortError,
)
from obsw.compat import Struct
from obsw.crc import crc16_ccitt

_HEAD = Struct(">BHB")
_new = object.__new__


def int_len(value):
    """Octets needed for an unsigned value (at least 1)."""
    n = 1
    while value >> (8 * n):
        n += 1
    return n


def uint_bytes(value, size):
    if value < 0 or value >> (8 * size):
        raise PduFormatError("value %d does not fit in %d octets" % (value, size))
    return value.to_bytes(size, "big")


def uint_from(buf, pos, size):
    return int.from_bytes(bytes(buf[pos : pos + size]), "big")


def fss_pack(large, value):
    """A file-size-sensitive field: 32 bits, or 64 bits in large-file mode."""
    if large:
        return struct.pack(">Q", value)
    if value >> 32:
        raise PduFormatError("offset %d needs large-file mode" % value)
    return struct.pack(">I", value)


def fss_unpack(large, buf, pos, what):
    size = 8 if large else 4
    if len(buf) < pos + size:
        raise PduTooShortError(what, pos + size, len(buf))
    return struct.unpack_from(">Q" if large else ">I", buf, pos)[0], pos + size


class PduHeader:
    """The fixed header: flags, entity ids and the transaction sequence number."""

    def __init__(
        self,
        source,
        dest,
        seq,
        *,
        pdu_type=FILE_DIRECTIVE,
        direction=TOWARD_RECEIVER,
        mode=UNACKNOWLEDGED,
        crc=False,
        large=False,
        seg_ctrl=False,
        seg_meta=False,
        eid_len=0,
        seq_len=0,
    ):
        self.source = source
        self.dest = dest
        self.seq = seq
        self.pdu_type = pdu_type
        self.direction = direction
        self.mode = mode
        self.crc = bool(crc)
        self.large = bool(large)
        self.seg_ctrl = bool(seg_ctrl)
        self.seg_meta = bool(seg_meta)
        self.eid_len = eid_len or max(int_len(source), int_len(dest))
        self.seq_len = seq_len or int_len(seq)
        self.data_len = 0  # PDU data field length (with CRC), set by pack/unpack
        if not 1 <= self.eid_len <= 8 or not 1 <= self.seq_len <= 8:
            raise PduFormatError(
                "entity id and sequence number lengths must be 1..8 octets, got %d and %d"
                % (self.eid_len, self.seq_len)
            )

    def copy(self, **changes):
        h = PduHeader(
            self.source,
            self.dest,
            self.seq,
            pdu_type=self.pdu_type,
            direction=self.direction,
            mode=self.mode,
            crc=self.crc,
            large=self.large,
            seg_ctrl=self.seg_ctrl,
            seg_meta=self.seg_meta,
            eid_len=self.eid_len,
            seq_len=self.seq_len,
        )
        for k in changes:
            setattr(h, k, changes[k])
        return h

    @property
    def length(self):
        return 4 + 2 * self.eid_len + self.seq_len

    def transaction_id(self):
        return (self.source, self.seq)

    def pack(self, data_len=None):
        if data_len is None:
            data_len = self.data_len
        if not 0 <= data_len <= 0xFFFF:
            raise PduFormatError("PDU data field of %d octets exceeds 65535" % data_len)
        b0 = (
            (VERSION << 5)
            | (self.pdu_type << 4)
            | (self.direction << 3)
            | (self.mode << 2)
            | (self.crc << 1)
            | self.large
        )
        b3 = (
            (self.seg_ctrl << 7)
            | ((self.eid_len - 1) << 4)
            | (self.seg_meta << 3)
            | (self.seq_len - 1)
        )
        e = self.eid_len
        return (
            struct.pack(">BHB", b0, data_len, b3)
            + uint_bytes(self.source, e)
            + uint_bytes(self.seq, self.seq_len)
            + uint_bytes(self.dest, e)
        )

    @classmethod
    def unpack(cls, buf):
        n = len(buf)
        if n < 4:
            raise PduTooShortError("PDU header", 4, n)
        b0, data_len, b3 = _HEAD.unpack_from(buf, 0)
        if b0 >> 5 != VERSION:
            raise PduFormatError("PDU version %d, expected %d" % (b0 >> 5, VERSION))
        e = ((b3 >> 4) & 7) + 1
        s = (b3 & 7) + 1
        size = 4 + 2 * e + s
        if n < size:
            raise PduTooShortError("PDU header", size, n)
        # the fields straight into a new object (no keyword call, no range checks: every
        # value a header can carry is a valid one)
        h = _new(cls)
        if e == 1 and s == 1:
            h.source = buf[4]
            h.seq = buf[5]
            h.dest = buf[6]
        else:
            h.source = uint_from(buf, 4, e)
            h.seq = uint_from(buf, 4 + e, s)
            h.dest = uint_from(buf, 4 + e + s, e)
        h.pdu_type = (b0 >> 4) & 1
        h.direction = (b0 >> 3) & 1
        h.mode = (b0 >> 2) & 1
        h.crc = bool(b0 & 2)
        h.large = bool(b0 & 1)
        h.seg_ctrl = bool(b3 & 0x80)
        h.seg_meta = bool(b3 & 8)
        h.eid_len = e
        h.seq_len = s
        h.data_len = data_len
        return h

    def __eq__(self, other):
        return isinstance(other, PduHeader) and self.pack(0) == other.pack(0)

    def __repr__(self):
        return "PduHeader(%d->%d #%d type=%d dir=%d mode=%d crc=%d large=%d len=%d)" % (
            self.source,
            self.dest,
            self.seq,
            self.pdu_type,
            self.direction,
            self.mode,
            self.crc,
            self.large,
            self.data_len,
        )


def split_pdu(buf):
    """Header and data field (a memoryview without the CRC) of one PDU; checks lengths and CRC."""
    h = PduHeader.unpack(buf)
    hl = 4 + 2 * h.eid_len + h.seq_len
    end = hl + h.data_len
    if len(buf) < end:
        raise PduTooShortError("PDU", end, len(buf))
    mv = memoryview(buf)
    if h.crc:
        if h.data_len < 2:
            raise PduTooShortError("PDU data field with CRC", 2, h.data_len)
        got = (buf[end - 2] << 8) | buf[end - 1]
        want = crc16_ccitt(mv[: end - 2])
        if got != want:
            raise PduCrcError(want, got)
        end -= 2
    return h, mv[hl:end]


def join_pdu(header, body):
    """Header and data field into one PDU, with the CRC when the header asks for one."""
    if header.crc:
        header.data_len = len(body) + 2
        out = header.pack() + body
        return out + struct.pack(">H", crc16_ccitt(out))
    header.data_len = len(body)
    return header.pack() + body


class Pdu:
    """Base of all PDUs: ``pack()`` and ``unpack(buf)``; subclasses give the data field."""

    def pack(self):
        return join_pdu(self.header, self.pack_body())

    @classmethod
    def unpack(cls, buf):
        h, body = split_pdu(buf)
        return cls.from_body(h, body)

    def _values(self):
        d = {}
        for k in self.__dict__:
            d[k] = self.__dict__[k]
        return d

    def __eq__(self, other):
        return type(self) is type(other) and self._values() == other._values()

    def __ne__(self, other):
        return not self.__eq__(other)

    def __repr__(self):
        return "%s(%s)" % (type(self).__name__, self._values())


def directive_body(pdu, header, body, code, minimum, name):
    """Check a directive PDU's data field: the right code and at least ``minimum`` octets."""
    if len(body) < minimum:
        raise PduTooShortError(name + " PDU data field", minimum, len(body))
    if header.pdu_type != FILE_DIRECTIVE or body[0] != code:
        raise PduFormatError(
            "%s PDU needs directive code 0x%02X, got 0x%02X" % (name, code, body[0])
        )
