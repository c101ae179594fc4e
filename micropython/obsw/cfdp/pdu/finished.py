"""CFDP Finished PDU (727.0-B-5 5.2.3)."""

from obsw.cfdp.defs import (
    DATA_COMPLETE,
    DIR_FINISHED,
    FILE_STATUS_UNREPORTED,
    NO_ERROR,
    TLV_ENTITY_ID,
    TLV_FILESTORE_RESPONSE,
    PduFormatError,
)
from obsw.cfdp.pdu.header import Pdu, directive_body
from obsw.cfdp.tlv import EntityIdTlv, pack_tlvs, unpack_tlv


class FinishedPdu(Pdu):
    """The receiver's verdict: condition, delivery code, file status, filestore responses."""

    CODE = DIR_FINISHED

    def __init__(
        self,
        header,
        condition=NO_ERROR,
        delivery=DATA_COMPLETE,
        file_status=FILE_STATUS_UNREPORTED,
        responses=(),
        fault_location=None,
    ):
        self.header = header
        self.condition = condition
        self.delivery = delivery
        self.file_status = file_status
        self.responses = list(responses)  # FilestoreResponse TLVs
        self.fault_location = fault_location

    def pack_body(self):
        out = bytes(
            (DIR_FINISHED, (self.condition << 4) | (self.delivery << 2) | self.file_status)
        ) + pack_tlvs(self.responses)
        if self.fault_location is not None:
            out += EntityIdTlv(self.fault_location, self.header.eid_len).pack()
        return out

    @classmethod
    def from_body(cls, header, body):
        directive_body(cls, header, body, DIR_FINISHED, 2, "Finished")
        responses = []
        loc = None
        pos = 2
        while pos < len(body):
            tlv, pos = unpack_tlv(body, pos)
            if tlv.tlv_type == TLV_FILESTORE_RESPONSE and loc is None:
                responses.append(tlv)
            elif tlv.tlv_type == TLV_ENTITY_ID and loc is None:
                loc = tlv.entity_id
            else:
                raise PduFormatError("Finished PDU: unexpected TLV type %d" % tlv.tlv_type)
        b = body[1]
        return cls(header, b >> 4, (b >> 2) & 1, b & 3, responses, loc)
