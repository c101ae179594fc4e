"""CFDP Metadata PDU (727.0-B-5 5.2.5)."""

from obsw.cfdp.defs import DIR_METADATA, TLV_FILESTORE_REQUEST, TLV_MESSAGE_TO_USER
from obsw.cfdp.pdu.header import Pdu, directive_body, fss_pack, fss_unpack
from obsw.cfdp.tlv import lv_name, lv_pack, pack_tlvs, unpack_tlvs
from obsw.crc import CHECKSUM_MODULAR


class MetadataPdu(Pdu):
    """Opens a transaction: file size, names, checksum type, closure flag and option TLVs.

    A transaction with no file (only messages to user or filestore requests) has both names
    ``None``.
    """

    CODE = DIR_METADATA

    def __init__(
        self,
        header,
        file_size,
        source_name,
        dest_name,
        checksum_type=CHECKSUM_MODULAR,
        closure=False,
        options=(),
    ):
        self.header = header
        self.file_size = file_size
        self.source_name = source_name or None
        self.dest_name = dest_name or None
        self.checksum_type = checksum_type
        self.closure = bool(closure)
        self.options = list(options)

    def _options_of(self, tlv_type):
        return [t for t in self.options if t.tlv_type == tlv_type]

    @property
    def filestore_requests(self):
        return self._options_of(TLV_FILESTORE_REQUEST)

    @property
    def messages_to_user(self):
        return self._options_of(TLV_MESSAGE_TO_USER)

    def pack_body(self):
        return (
            bytes((DIR_METADATA, (self.closure << 6) | (self.checksum_type & 15)))
            + fss_pack(self.header.large, self.file_size)
            + lv_pack(self.source_name or "")
            + lv_pack(self.dest_name or "")
            + pack_tlvs(self.options)
        )

    @classmethod
    def from_body(cls, header, body):
        directive_body(cls, header, body, DIR_METADATA, 2, "Metadata")
        size, pos = fss_unpack(header.large, body, 2, "Metadata PDU file size")
        src, pos = lv_name(body, pos, "Metadata PDU source file name")
        dst, pos = lv_name(body, pos, "Metadata PDU destination file name")
        return cls(
            header, size, src, dst, body[1] & 15, (body[1] >> 6) & 1, unpack_tlvs(body, pos)
        )
