"""CFDP Keep Alive PDU (727.0-B-5 5.2.8)."""

from obsw.cfdp.defs import DIR_KEEP_ALIVE
from obsw.cfdp.pdu.header import Pdu, directive_body, fss_pack, fss_unpack


class KeepAlivePdu(Pdu):
    """The receiver's progress: the offset up to which all data has arrived."""

    CODE = DIR_KEEP_ALIVE

    def __init__(self, header, progress):
        self.header = header
        self.progress = progress

    def pack_body(self):
        return bytes((DIR_KEEP_ALIVE,)) + fss_pack(self.header.large, self.progress)

    @classmethod
    def from_body(cls, header, body):
        directive_body(cls, header, body, DIR_KEEP_ALIVE, 1, "Keep Alive")
        progress, _ = fss_unpack(header.large, body, 1, "Keep Alive PDU progress")
        return cls(header, progress)
