"""CFDP Prompt PDU (727.0-B-5 5.2.7)."""

from obsw.cfdp.defs import DIR_PROMPT
from obsw.cfdp.pdu.header import Pdu, directive_body


class PromptPdu(Pdu):
    """Asks the receiver for a NAK (``PROMPT_NAK``) or a keep-alive (``PROMPT_KEEP_ALIVE``)."""

    CODE = DIR_PROMPT

    def __init__(self, header, response):
        self.header = header
        self.response = response

    def pack_body(self):
        return bytes((DIR_PROMPT, self.response << 7))

    @classmethod
    def from_body(cls, header, body):
        directive_body(cls, header, body, DIR_PROMPT, 2, "Prompt")
        return cls(header, body[1] >> 7)
