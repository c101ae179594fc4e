"""CFDP EOF PDU (727.0-B-5 5.2.2)."""

import struct

from obsw.cfdp.defs import DIR_EOF, NO_ERROR, TLV_ENTITY_ID, PduFormatError
from obsw.cfdp.pdu.header import Pdu, directive_body, fss_pack, fss_unpack
from obsw.cfdp.tlv import EntityIdTlv, unpack_tlv


class EofPdu(Pdu):
    """End of file: condition code, file checksum, file size and, after a fault, its location."""

    CODE = DIR_EOF

    def __init__(self, header, condition, checksum, file_size, fault_location=None):
        self.header = header
        self.condition = condition
        self.checksum = checksum
        self.file_size = file_size
        self.fault_location = fault_location  # an entity id, or None

    def pack_body(self):
        out = struct.pack(">BBI", DIR_EOF, self.condition << 4, self.checksum) + fss_pack(
            self.header.large, self.file_size
        )
        if self.condition != NO_ERROR and self.fault_location is not None:
            out += EntityIdTlv(self.fault_location, self.header.eid_len).pack()
        return out

    @classmethod
    def from_body(cls, header, body):
        directive_body(cls, header, body, DIR_EOF, 6, "EOF")
        checksum = struct.unpack_from(">I", body, 2)[0]
        size, pos = fss_unpack(header.large, body, 6, "EOF PDU file size")
        loc = None
        if pos < len(body):
            tlv, pos = unpack_tlv(body, pos)
            if tlv.tlv_type != TLV_ENTITY_ID:
                raise PduFormatError("EOF PDU fault location must be an entity id TLV")
            loc = tlv.entity_id
        return cls(header, body[1] >> 4, checksum, size, loc)
