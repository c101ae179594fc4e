"""CFDP PDU codecs: one module per PDU; ``decode_pdu`` picks the right one from the bytes."""

from obsw.cfdp.defs import (
    DIR_ACK,
    DIR_EOF,
    DIR_FINISHED,
    DIR_KEEP_ALIVE,
    DIR_METADATA,
    DIR_NAK,
    DIR_PROMPT,
    FILE_DATA,
    PduFormatError,
    PduTooShortError,
)
from obsw.cfdp.pdu.header import split_pdu


def _classes():
    # imported on first use so that a user of one PDU type does not load them all
    from obsw.cfdp.pdu.ack import AckPdu
    from obsw.cfdp.pdu.eof import EofPdu
    from obsw.cfdp.pdu.finished import FinishedPdu
    from obsw.cfdp.pdu.keepalive import KeepAlivePdu
    from obsw.cfdp.pdu.metadata import MetadataPdu
    from obsw.cfdp.pdu.nak import NakPdu
    from obsw.cfdp.pdu.prompt import PromptPdu

    return {
        DIR_EOF: EofPdu,
        DIR_FINISHED: FinishedPdu,
        DIR_ACK: AckPdu,
        DIR_METADATA: MetadataPdu,
        DIR_NAK: NakPdu,
        DIR_PROMPT: PromptPdu,
        DIR_KEEP_ALIVE: KeepAlivePdu,
    }


_DIRECTIVES = {}
_FILE_DATA = []  # FileDataPdu.from_body, once imported


def decode_pdu(buf):
    """Decode any CFDP PDU; raises a ``CfdpError`` subclass for malformed input."""
    header, body = split_pdu(buf)
    if header.pdu_type == FILE_DATA:
        if not _FILE_DATA:
            from obsw.cfdp.pdu.filedata import FileDataPdu

            _FILE_DATA.append(FileDataPdu.from_body)
        return _FILE_DATA[0](header, body)
    if not body:
        raise PduTooShortError("file directive PDU data field", 1, 0)
    if not _DIRECTIVES:
        _DIRECTIVES.update(_classes())
    cls = _DIRECTIVES.get(body[0])
    if cls is None:
        raise PduFormatError("unknown file directive code 0x%02X" % body[0])
    return cls.from_body(header, body)
