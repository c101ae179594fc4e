"""CFDP LV and TLV fields (727.0-B-5 5.1.8, 5.4): filestore requests and responses, messages to
user, fault handler overrides, flow labels and entity ids."""

from obsw.cfdp.defs import (
    FS_TWO_NAMES,
    TLV_ENTITY_ID,
    TLV_FAULT_HANDLER,
    TLV_FILESTORE_REQUEST,
    TLV_FILESTORE_RESPONSE,
    TLV_FLOW_LABEL,
    TLV_MESSAGE_TO_USER,
    PduFormatError,
    PduTooShortError,
)


def lv_pack(value):
    """Length-value: one length octet, then up to 255 octets (str is UTF-8 encoded)."""
    if isinstance(value, str):
        value = value.encode()
    if len(value) > 255:
        raise PduFormatError("LV value of %d octets exceeds 255" % len(value))
    return bytes((len(value),)) + value


def lv_unpack(buf, pos, what="LV"):
    """(value bytes, next position)."""
    if len(buf) < pos + 1:
        raise PduTooShortError(what, pos + 1, len(buf))
    end = pos + 1 + buf[pos]
    if len(buf) < end:
        raise PduTooShortError(what, end, len(buf))
    return bytes(buf[pos + 1 : end]), end


def decode_name(raw, what="file name"):
    try:
        return raw.decode()
    except Exception:  # UnicodeError on CPython, on MicroPython too, but keep it broad
        raise PduFormatError("%s is not UTF-8: %r" % (what, raw)) from None


def lv_name(buf, pos, what="file name"):
    raw, pos = lv_unpack(buf, pos, what)
    return decode_name(raw, what), pos


class Tlv:
    """A type-length-value field of a type this entity does not interpret."""

    def __init__(self, tlv_type, value=b""):
        self.tlv_type = tlv_type
        self.value = bytes(value)

    def value_bytes(self):
        return self.value

    def pack(self):
        v = self.value_bytes()
        if len(v) > 255:
            raise PduFormatError("TLV value of %d octets exceeds 255" % len(v))
        return bytes((self.tlv_type, len(v))) + v

    @classmethod
    def unpack(cls, buf):
        tlv, _ = unpack_tlv(buf, 0)
        return tlv

    def __eq__(self, other):
        return (
            isinstance(other, Tlv)
            and self.tlv_type == other.tlv_type
            and self.value_bytes() == other.value_bytes()
        )

    def __ne__(self, other):
        return not self.__eq__(other)

    def __repr__(self):
        return "%s(%r)" % (type(self).__name__, self.value_bytes())


class FilestoreRequest(Tlv):
    """Filestore request: action code and one or two file names (table 5-15)."""

    def __init__(self, action, first, second=None):
        self.tlv_type = TLV_FILESTORE_REQUEST
        self.action = action
        self.first = first
        self.second = second

    def value_bytes(self):
        out = bytes((self.action << 4,)) + lv_pack(self.first)
        if self.action in FS_TWO_NAMES:
            out += lv_pack(self.second or "")
        return out

    @classmethod
    def from_value(cls, v):
        if len(v) < 2:
            raise PduTooShortError("filestore request TLV", 2, len(v))
        action = v[0] >> 4
        first, pos = lv_name(v, 1)
        second = None
        if action in FS_TWO_NAMES:
            second, pos = lv_name(v, pos)
        return cls(action, first, second)

    def __repr__(self):
        return "FilestoreRequest(%d, %r, %r)" % (self.action, self.first, self.second)


class FilestoreResponse(Tlv):
    """Filestore response: action, status code, file names and an optional message."""

    def __init__(self, action, status, first, second=None, message=b""):
        self.tlv_type = TLV_FILESTORE_RESPONSE
        self.action = action
        self.status = status
        self.first = first
        self.second = second
        self.message = bytes(message)

    def value_bytes(self):
        out = bytes(((self.action << 4) | self.status,)) + lv_pack(self.first)
        if self.action in FS_TWO_NAMES:
            out += lv_pack(self.second or "")
        return out + lv_pack(self.message)

    @classmethod
    def from_value(cls, v):
        if len(v) < 2:
            raise PduTooShortError("filestore response TLV", 2, len(v))
        action = v[0] >> 4
        first, pos = lv_name(v, 1)
        second = None
        if action in FS_TWO_NAMES:
            second, pos = lv_name(v, pos)
        message = b""
        if pos < len(v):
            message, pos = lv_unpack(v, pos, "filestore message")
        return cls(action, v[0] & 15, first, second, message)

    def __repr__(self):
        return "FilestoreResponse(%d, %d, %r, %r, %r)" % (
            self.action,
            self.status,
            self.first,
            self.second,
            self.message,
        )


class MessageToUser(Tlv):
    """Message to user: opaque octets (reserved CFDP messages start with b'cfdp')."""

    def __init__(self, value=b""):
        self.tlv_type = TLV_MESSAGE_TO_USER
        self.value = bytes(value)

    @classmethod
    def from_value(cls, v):
        return cls(v)


class FaultHandlerOverride(Tlv):
    """Fault handler override: a condition code and the handler to use for it."""

    def __init__(self, condition, handler):
        self.tlv_type = TLV_FAULT_HANDLER
        self.condition = condition
        self.handler = handler

    def value_bytes(self):
        return bytes(((self.condition << 4) | self.handler,))

    @classmethod
    def from_value(cls, v):
        if len(v) < 1:
            raise PduTooShortError("fault handler override TLV", 1, 0)
        return cls(v[0] >> 4, v[0] & 15)

    def __repr__(self):
        return "FaultHandlerOverride(%d, %d)" % (self.condition, self.handler)


class FlowLabel(Tlv):
    """Flow label: octets whose meaning the local implementation defines."""

    def __init__(self, value=b""):
        self.tlv_type = TLV_FLOW_LABEL
        self.value = bytes(value)

    @classmethod
    def from_value(cls, v):
        return cls(v)


class EntityIdTlv(Tlv):
    """Entity id TLV (the fault location of EOF and Finished PDUs)."""

    def __init__(self, entity_id, size=0):
        from obsw.cfdp.pdu.header import int_len

        self.tlv_type = TLV_ENTITY_ID
        self.entity_id = entity_id
        self.size = size or int_len(entity_id)

    def value_bytes(self):
        from obsw.cfdp.pdu.header import uint_bytes

        return uint_bytes(self.entity_id, self.size)

    @classmethod
    def from_value(cls, v):
        if not 1 <= len(v) <= 8:
            raise PduFormatError("entity id TLV of %d octets, expected 1..8" % len(v))
        return cls(int.from_bytes(bytes(v), "big"), len(v))

    def __repr__(self):
        return "EntityIdTlv(%d)" % self.entity_id


_TYPES = {
    TLV_FILESTORE_REQUEST: FilestoreRequest,
    TLV_FILESTORE_RESPONSE: FilestoreResponse,
    TLV_MESSAGE_TO_USER: MessageToUser,
    TLV_FAULT_HANDLER: FaultHandlerOverride,
    TLV_FLOW_LABEL: FlowLabel,
    TLV_ENTITY_ID: EntityIdTlv,
}


def unpack_tlv(buf, pos):
    """(TLV object, next position): a typed object for the types above, else a plain Tlv."""
    if len(buf) < pos + 2:
        raise PduTooShortError("TLV", pos + 2, len(buf))
    t = buf[pos]
    end = pos + 2 + buf[pos + 1]
    if len(buf) < end:
        raise PduTooShortError("TLV", end, len(buf))
    v = bytes(buf[pos + 2 : end])
    cls = _TYPES.get(t)
    return (cls.from_value(v) if cls else Tlv(t, v)), end


def unpack_tlvs(buf, pos=0):
    out = []
    n = len(buf)
    while pos < n:
        tlv, pos = unpack_tlv(buf, pos)
        out.append(tlv)
    return out


def pack_tlvs(tlvs):
    return b"".join([t.pack() for t in tlvs])
