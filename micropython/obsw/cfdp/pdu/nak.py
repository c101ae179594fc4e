"""CFDP NAK PDU (727.0-B-5 5.2.6)."""

from obsw.cfdp.defs import DIR_NAK, PduFormatError
from obsw.cfdp.pdu.header import Pdu, directive_body, fss_pack, fss_unpack


class NakPdu(Pdu):
    """Requests retransmission: a scope and (start, end) pairs; (0, 0) asks for the metadata."""

    CODE = DIR_NAK

    def __init__(self, header, start, end, segments=()):
        self.header = header
        self.start = start
        self.end = end
        self.segments = [tuple(s) for s in segments]

    @staticmethod
    def max_segments(header, max_pdu):
        """How many segment requests fit in a NAK PDU of at most ``max_pdu`` octets."""
        fss = 8 if header.large else 4
        room = max_pdu - header.length - (2 if header.crc else 0) - 1 - 2 * fss
        return max(1, room // (2 * fss))

    def pack_body(self):
        large = self.header.large
        parts = [bytes((DIR_NAK,)), fss_pack(large, self.start), fss_pack(large, self.end)]
        for s, e in self.segments:
            parts.append(fss_pack(large, s))
            parts.append(fss_pack(large, e))
        return b"".join(parts)

    @classmethod
    def from_body(cls, header, body):
        large = header.large
        fss = 8 if large else 4
        directive_body(cls, header, body, DIR_NAK, 1 + 2 * fss, "NAK")
        start, pos = fss_unpack(large, body, 1, "NAK scope")
        end, pos = fss_unpack(large, body, pos, "NAK scope")
        if (len(body) - pos) % (2 * fss):
            raise PduFormatError(
                "NAK PDU segment requests: %d octets is not a multiple of %d"
                % (len(body) - pos, 2 * fss)
            )
        segs = []
        while pos < len(body):
            s, pos = fss_unpack(large, body, pos, "NAK segment")
            e, pos = fss_unpack(large, body, pos, "NAK segment")
            segs.append((s, e))
        return cls(header, start, end, segs)
