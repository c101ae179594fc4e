"""CFDP ACK PDU (727.0-B-5 5.2.4)."""

from obsw.cfdp.defs import DIR_ACK, DIR_FINISHED, STATUS_ACTIVE
from obsw.cfdp.pdu.header import Pdu, directive_body


class AckPdu(Pdu):
    """Acknowledges an EOF (sent by the receiver) or a Finished PDU (sent by the sender)."""

    CODE = DIR_ACK

    def __init__(self, header, directive, condition, status=STATUS_ACTIVE):
        self.header = header
        self.directive = directive  # DIR_EOF or DIR_FINISHED
        self.condition = condition
        self.status = status

    def pack_body(self):
        sub = 1 if self.directive == DIR_FINISHED else 0
        return bytes((DIR_ACK, (self.directive << 4) | sub, (self.condition << 4) | self.status))

    @classmethod
    def from_body(cls, header, body):
        directive_body(cls, header, body, DIR_ACK, 3, "ACK")
        return cls(header, body[1] >> 4, body[2] >> 4, body[2] & 3)
