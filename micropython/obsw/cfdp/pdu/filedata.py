"""CFDP File Data PDU (727.0-B-5 5.3), with optional segment metadata."""

from obsw.cfdp.defs import FILE_DATA, PduFormatError, PduTooShortError
from obsw.cfdp.pdu.header import Pdu, fss_pack, fss_unpack
from obsw.compat import Struct

_OFFSET = Struct(">I")
_new = object.__new__


class FileDataPdu(Pdu):
    """A file segment at ``offset``; record continuation state and segment metadata are sent
    only when the header's segment metadata flag is set."""

    CODE = None  # file data carries no directive code

    def __init__(self, header, offset, data, rcs=0, segment_metadata=b""):
        self.header = header
        self.offset = offset
        self.data = bytes(data)
        self.rcs = rcs
        self.segment_metadata = bytes(segment_metadata)

    def pack_body(self):
        if self.header.seg_meta:
            meta = self.segment_metadata
            if len(meta) > 63:
                raise PduFormatError("segment metadata of %d octets exceeds 63" % len(meta))
            lead = bytes(((self.rcs << 6) | len(meta),)) + meta
        else:
            lead = b""
        return lead + fss_pack(self.header.large, self.offset) + self.data

    @classmethod
    def from_body(cls, header, body):
        if header.pdu_type != FILE_DATA:
            raise PduFormatError("File Data PDU needs PDU type 1, got a file directive")
        if not (header.seg_meta or header.large) and len(body) >= 4:
            # the usual segment: a 32-bit offset and the data, built without __init__
            pdu = _new(cls)
            pdu.header = header
            pdu.offset = _OFFSET.unpack_from(body, 0)[0]
            pdu.data = bytes(body[4:])
            pdu.rcs = 0
            pdu.segment_metadata = b""
            return pdu
        pos = 0
        rcs = 0
        meta = b""
        if header.seg_meta:
            if len(body) < 1:
                raise PduTooShortError("File Data PDU segment metadata", 1, 0)
            rcs = body[0] >> 6
            pos = 1 + (body[0] & 63)
            if len(body) < pos:
                raise PduTooShortError("File Data PDU segment metadata", pos, len(body))
            meta = bytes(body[1:pos])
        offset, pos = fss_unpack(header.large, body, pos, "File Data PDU offset")
        return cls(header, offset, body[pos:], rcs, meta)
