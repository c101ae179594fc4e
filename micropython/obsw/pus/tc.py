"""PUS-C telecommand packets (ECSS-E-ST-70-41C 7.4.3): TC secondary header, app data, PEC."""

from obsw.compat import STRUCT_CHECKS_RANGES, const, pus_accelerator
from obsw.crc import crc16_ccitt_update as _crc
from obsw.pus.config import DEFAULT
from obsw.pus.packets import (
    ACK_ALL,
    PUS_VERSION,
    PusPacket,
    PusVersionError,
    RequestId,
    check_range,
    read_int,
)
from obsw.spp import SEQ_UNSEGMENTED, TYPE_TC, FieldRangeError

_TC_ID = const(0x1800)  # version 0, type 1 (TC), secondary header flag 1
_new = object.__new__
_LAX = not STRUCT_CHECKS_RANGES  # check every field in Python, struct will not
_C = pus_accelerator()  # the C codec; config.tc_fast is 0 whenever this is None
_c_pack = _C.tc_pack_slots if _C is not None else None
_c_unpack = _C.tc_unpack if _C is not None else None


class PusTc(PusPacket):
    """A PUS-C telecommand: primary header, TC secondary header, application data, PEC."""

    __slots__ = (
        "apid",
        "service",
        "subtype",
        "data",
        "seq_count",
        "ack",
        "source_id",
        "seq_flags",
        "config",
    )
    packet_type = TYPE_TC
    KIND = "TC"
    ID = _TC_ID

    def __init__(
        self,
        apid,
        service,
        subtype,
        data=b"",
        seq_count=0,
        ack=ACK_ALL,
        source_id=0,
        seq_flags=SEQ_UNSEGMENTED,
        config=DEFAULT,
    ):
        self.apid = apid
        self.service = service
        self.subtype = subtype
        self.data = data  # application data
        self.seq_count = seq_count  # packet sequence count or packet name
        self.ack = ack
        self.source_id = source_id
        self.seq_flags = seq_flags
        self.config = config

    def request_id(self):
        return RequestId.from_words(_TC_ID | self.apid, (self.seq_flags << 14) | self.seq_count)

    def pack(self):
        c = self.config
        f = c.tc_fast
        if f:
            # the C codec packs what it can vouch for and returns None for anything odd
            raw = _c_pack(self, f)  # reads the fields straight from the slots
            if raw is not None:
                return raw
        data = self.data
        apid = self.apid
        count = self.seq_count
        flags = self.seq_flags
        ack = self.ack
        total = c.tc_min_size + len(data)
        # Python checks the upper bounds of the fields narrower than a struct code; struct.pack
        # refuses the rest (a negative value makes its header word negative too).
        if apid > 0x7FF or count > 0x3FFF or flags > 3 or ack > 15 or _LAX and self._lax(c):
            self._check(c, total)
        s = c.tc_struct
        if s is None:
            return self._pack_fields(c, total)
        try:
            head = (
                s.pack(
                    _TC_ID | apid,
                    (flags << 14) | count,
                    total - 7,
                    0x20 | ack,
                    self.service,
                    self.subtype,
                    self.source_id,
                )
                + data
            )
        except Exception:
            e = self._refused(c, total)
            if e is None:
                raise
            raise e from None
        return self._sealed(c, total, head)

    def _pack_fields(self, c, total):
        # layouts without one struct for the whole header (3-octet source ID, spare octets)
        if self._lax(c):
            self._check(c, total)
        elif total > c.max_packet_size:
            raise FieldRangeError("TC packet length", total, c.max_packet_size)
        head = c.tc_common.pack(
            self.packet_id,
            self.sequence_control,
            total - 7,
            0x20 | self.ack,
            self.service,
            self.subtype,
        )
        if c.source_id_size:
            head += self.source_id.to_bytes(c.source_id_size, "big")
        if c.tc_spare:
            head += bytes(c.tc_spare)
        return self._sealed(c, total, head + self.data)

    def _lax(self, c):
        # True if a value is negative or too wide for its octets: what struct.pack refuses on
        # CPython but lets through truncated on MicroPython (pack() tests the upper bounds of
        # the fields narrower than a struct code itself)
        return (
            (self.apid | self.seq_count | self.seq_flags | self.ack) < 0
            or (self.service | self.subtype) >> 8
            or self.source_id >> c.source_id_bits
        )

    def _check(self, c, total=0):
        # every field in turn, then the packet length: the first that is wrong raises
        self._check_primary()
        check_range("acknowledgement flags", self.ack, 15)
        check_range("source ID", self.source_id, c.source_id_max)
        if total > c.max_packet_size:
            raise FieldRangeError("TC packet length", total, c.max_packet_size)

    @classmethod
    def unpack(cls, buf, config=DEFAULT):
        """Decode a buffer holding exactly one TC; raises a PusError subclass if malformed."""
        f = config.tc_fast
        if f:
            tc = _c_unpack(cls, buf, f, config)  # None unless well-formed
            if tc is not None:
                return tc
        s = config.tc_struct
        n = len(buf)
        if s is not None and n >= config.tc_min_size:
            # fast path for a well-formed packet; anything odd goes the careful way below
            pid, psc, dlen, b0, svc, sub, src = s.unpack_from(buf, 0)
            if (
                pid & 0xF800 == _TC_ID
                and dlen + 7 == n
                and b0 >> 4 == PUS_VERSION
                and n <= config.max_packet_size
                and (not config.pec or not _crc(buf, 0xFFFF))
            ):
                data = buf[config.tc_data_offset : n - config.pec_size]
                tc = _new(cls)
                tc.apid = pid & 0x7FF
                tc.service = svc
                tc.subtype = sub
                tc.data = data if data.__class__ is bytes else bytes(data)
                tc.seq_count = psc & 0x3FFF
                tc.ack = b0 & 15
                tc.source_id = src
                tc.seq_flags = psc >> 14
                tc.config = config
                return tc
        return cls._decode(buf, 0, config, True)[0]

    @classmethod
    def _decode(cls, buf, offset, config, exact):
        pid, psc, end, data_end = cls._frame(buf, offset, config, exact, config.tc_min_size)
        s = config.tc_struct
        if s is not None:
            b0, svc, sub, src = s.unpack_from(buf, offset)[3:]
        else:
            b0, svc, sub = config.tc_common.unpack_from(buf, offset)[3:]
            src = read_int(buf, offset + 9, config.source_id_size)
        if b0 >> 4 != PUS_VERSION:
            raise PusVersionError("TC", b0 >> 4, pid, psc)
        tc = cls(
            pid & 0x7FF,
            svc,
            sub,
            bytes(buf[offset + config.tc_data_offset : data_end]),
            psc & 0x3FFF,
            b0 & 15,
            src,
            psc >> 14,
            config,
        )
        return tc, end

    def __eq__(self, other):
        return (
            isinstance(other, PusTc)
            and self.apid == other.apid
            and self.service == other.service
            and self.subtype == other.subtype
            and bytes(self.data) == bytes(other.data)
            and self.seq_count == other.seq_count
            and self.ack == other.ack
            and self.source_id == other.source_id
            and self.seq_flags == other.seq_flags
        )

    def __repr__(self):
        return "PusTc(TC[%d,%d], apid=%d, seq=%d, ack=0x%x, source=%d, %d bytes)" % (
            self.service,
            self.subtype,
            self.apid,
            self.seq_count,
            self.ack,
            self.source_id,
            len(self.data),
        )
