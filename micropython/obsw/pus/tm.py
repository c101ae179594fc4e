"""PUS-C telemetry packets (ECSS-E-ST-70-41C 7.4.2): TM secondary header, source data, PEC."""

from obsw.compat import STRUCT_CHECKS_RANGES, const, pus_accelerator
from obsw.crc import crc16_ccitt_update as _crc
from obsw.pus.config import DEFAULT
from obsw.pus.packets import (
    PUS_VERSION,
    PusHeaderError,
    PusPacket,
    PusVersionError,
    check_range,
    read_int,
)
from obsw.spp import SEQ_UNSEGMENTED, TYPE_TM, FieldRangeError
from obsw.timecode import TimeCodeError

_TM_ID = const(0x0800)  # version 0, type 0 (TM), secondary header flag 1
_NO_TIME = (0, 0)  # what time=None packs as in the struct layouts
_new = object.__new__
_LAX = not STRUCT_CHECKS_RANGES  # check every field in Python, struct will not
_C = pus_accelerator()  # the C codec; config.tm_fast is 0 whenever this is None
_c_pack = _C.tm_pack_slots if _C is not None else None
_c_unpack = _C.tm_unpack if _C is not None else None


class PusTm(PusPacket):
    """A PUS-C telemetry packet: primary header, TM secondary header, source data, PEC.

    ``time`` is the tuple the configured time code packs, e.g. ``(coarse, fine)`` for CUC;
    None packs as all zeros.
    """

    __slots__ = (
        "apid",
        "service",
        "subtype",
        "data",
        "seq_count",
        "message_counter",
        "destination_id",
        "time",
        "time_ref",
        "seq_flags",
        "config",
    )
    packet_type = TYPE_TM
    KIND = "TM"
    ID = _TM_ID

    def __init__(
        self,
        apid,
        service,
        subtype,
        data=b"",
        seq_count=0,
        message_counter=0,
        destination_id=0,
        time=None,
        time_ref=0,
        seq_flags=SEQ_UNSEGMENTED,
        config=DEFAULT,
    ):
        self.apid = apid
        self.service = service
        self.subtype = subtype
        self.data = data  # source data
        self.seq_count = seq_count
        self.message_counter = message_counter
        self.destination_id = destination_id
        self.time = time
        self.time_ref = time_ref  # spacecraft time reference status
        self.seq_flags = seq_flags
        self.config = config

    def _check(self, c, total=0, time=True):
        # every header field in turn, the packet length, then the time: the first wrong raises
        self._check_primary()
        check_range("time reference status", self.time_ref, 15)
        check_range("message type counter", self.message_counter, c.message_counter_max)
        check_range("destination ID", self.destination_id, c.destination_id_max)
        if total > c.max_packet_size:
            raise FieldRangeError("TM packet length", total, c.max_packet_size)
        tf = c.time_fields
        if time and tf is not None and self.time is not None:
            check_range("time coarse", self.time[0], (1 << tf[0]) - 1)
            check_range("time fine", self.time[1], (1 << tf[1]) - 1)

    def pack(self):
        c = self.config
        f = c.tm_fast
        if f:
            # the C codec packs what it can vouch for and returns None for anything odd
            raw = _c_pack(self, f)  # reads the fields straight from the slots
            if raw is not None:
                return raw
        data = self.data
        apid = self.apid
        count = self.seq_count
        flags = self.seq_flags
        ref = self.time_ref
        total = c.tm_min_size + len(data)
        # Python checks the upper bounds of the fields narrower than a struct code; struct.pack
        # refuses the rest (a negative value makes its header word negative too).
        if apid > 0x7FF or count > 0x3FFF or flags > 3 or ref > 15 or _LAX and self._lax(c):
            self._check(c, total)
        s = c.tm_struct
        if s is None:
            return self._pack_fields(c, total)
        t = self.time
        if _LAX and t is not None:
            self._lax_time(c, total, t)
        coarse, fine = _NO_TIME if t is None else t
        try:
            head = (
                s.pack(
                    _TM_ID | apid,
                    (flags << 14) | count,
                    total - 7,
                    0x20 | ref,
                    self.service,
                    self.subtype,
                    self.message_counter,
                    self.destination_id,
                    coarse,
                    fine,
                )
                + data
            )
        except Exception:
            e = self._refused(c, total)
            if e is None:
                raise
            raise e from None
        return self._sealed(c, total, head)

    def _lax(self, c):
        # True if a value is negative or too wide for its octets: what struct.pack refuses on
        # CPython but lets through truncated on MicroPython (pack() tests the upper bounds of
        # the fields narrower than a struct code itself)
        return (
            (self.apid | self.seq_count | self.seq_flags | self.time_ref) < 0
            or (self.service | self.subtype) >> 8
            | self.message_counter >> c.message_counter_bits
            | self.destination_id >> c.destination_id_bits
        )

    def _lax_time(self, c, total, t):
        # the time range checks struct.pack makes on CPython, in the order pack() always had
        coarse, fine = t
        tf = c.time_fields
        if coarse >> tf[0] | fine >> tf[1]:
            if total > c.max_packet_size:
                raise FieldRangeError("TM packet length", total, c.max_packet_size)
            self._check(c, total)

    def _pack_fields(self, c, total):
        # layouts without one struct for the whole header (odd field sizes, other time codes)
        if self._lax(c):
            self._check(c, total, False)  # the time code checks the time as it packs it
        elif total > c.max_packet_size:
            raise FieldRangeError("TM packet length", total, c.max_packet_size)
        head = c.tc_common.pack(
            self.packet_id,
            self.sequence_control,
            total - 7,
            0x20 | self.time_ref,
            self.service,
            self.subtype,
        )
        if c.message_counter_size:
            head += self.message_counter.to_bytes(c.message_counter_size, "big")
        if c.destination_id_size:
            head += self.destination_id.to_bytes(c.destination_id_size, "big")
        code = c.time
        t = self.time
        if code is not None:
            try:
                head += code.pack(*t) if t is not None else code.pack_seconds(0)
            except TimeCodeError as e:
                raise FieldRangeError("time", t, code.size) from e
        if c.tm_spare:
            head += bytes(c.tm_spare)
        return self._sealed(c, total, head + self.data)

    @classmethod
    def unpack(cls, buf, config=DEFAULT):
        """Decode a buffer holding exactly one TM; raises a PusError subclass if malformed."""
        f = config.tm_fast
        if f:
            tm = _c_unpack(cls, buf, f, config)  # None unless well-formed
            if tm is not None:
                return tm
        s = config.tm_struct
        n = len(buf)
        if s is not None and n >= config.tm_min_size:
            # fast path for a well-formed packet; anything odd goes the careful way below
            pid, psc, dlen, b0, svc, sub, cnt, dest, coarse, fine = s.unpack_from(buf, 0)
            if (
                pid & 0xF800 == _TM_ID
                and dlen + 7 == n
                and b0 & 0xF0 == 0x20
                and n <= config.max_packet_size
                and (not config.pec or _crc(buf, 0xFFFF) == 0)
            ):
                data = buf[config.tm_data_offset : n - config.pec_size]
                tm = _new(cls)
                tm.apid = pid & 0x7FF
                tm.service = svc
                tm.subtype = sub
                tm.data = data if data.__class__ is bytes else bytes(data)
                tm.seq_count = psc & 0x3FFF
                tm.message_counter = cnt
                tm.destination_id = dest
                tm.time = (coarse, fine)
                tm.time_ref = b0 & 15
                tm.seq_flags = psc >> 14
                tm.config = config
                return tm
        return cls._decode(buf, 0, config, True)[0]

    @classmethod
    def _decode(cls, buf, offset, config, exact):
        pid, psc, end, data_end = cls._frame(buf, offset, config, exact, config.tm_min_size)
        s = config.tm_struct
        if s is not None:
            b0, svc, sub, cnt, dest, coarse, fine = s.unpack_from(buf, offset)[3:]
            t = (coarse, fine)
        else:
            b0, svc, sub = config.tc_common.unpack_from(buf, offset)[3:]
            pos = offset + 9
            cnt = read_int(buf, pos, config.message_counter_size)
            pos += config.message_counter_size
            dest = read_int(buf, pos, config.destination_id_size)
            pos += config.destination_id_size
            t = None
            if config.time is not None:
                try:
                    t = config.time.unpack(buf, pos)
                except TimeCodeError as e:
                    raise PusHeaderError(
                        "TM", "time field", config.time, str(e), pid, psc
                    ) from None
        if b0 >> 4 != PUS_VERSION:
            raise PusVersionError("TM", b0 >> 4, pid, psc)
        tm = cls(
            pid & 0x7FF,
            svc,
            sub,
            bytes(buf[offset + config.tm_data_offset : data_end]),
            psc & 0x3FFF,
            cnt,
            dest,
            t,
            b0 & 15,
            psc >> 14,
            config,
        )
        return tm, end

    def __eq__(self, other):
        return (
            isinstance(other, PusTm)
            and self.apid == other.apid
            and self.service == other.service
            and self.subtype == other.subtype
            and bytes(self.data) == bytes(other.data)
            and self.seq_count == other.seq_count
            and self.message_counter == other.message_counter
            and self.destination_id == other.destination_id
            and _time(self) == _time(other)
            and self.time_ref == other.time_ref
            and self.seq_flags == other.seq_flags
        )

    def __repr__(self):
        return "PusTm(TM[%d,%d], apid=%d, seq=%d, counter=%d, dest=%d, time=%r, %d bytes)" % (
            self.service,
            self.subtype,
            self.apid,
            self.seq_count,
            self.message_counter,
            self.destination_id,
            self.time,
            len(self.data),
        )


def _time(tm):
    t = tm.time
    if t is None:
        return None
    t = tuple(t)
    return None if not any(t) else t
