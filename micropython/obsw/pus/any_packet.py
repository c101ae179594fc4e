"""A PUS packet of either kind: a TC or a TM, chosen by the primary header's packet type bit."""

from obsw.pus.config import DEFAULT
from obsw.pus.tc import PusTc
from obsw.pus.tm import PusTm


def unpack_packet(buf, config=DEFAULT):
    """A PusTc or PusTm, chosen by the packet type bit of the primary header."""
    if len(buf) >= 1 and buf[0] & 0x10:
        return PusTc.unpack(buf, config)
    return PusTm.unpack(buf, config)
