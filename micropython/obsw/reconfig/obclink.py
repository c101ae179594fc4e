"""The UART link between the OBC and the reconfiguration module: small CRC-checked frames.

Frame: ``0xA5 0x5A, type u8, length u8, payload, CRC-16/CCITT-FALSE u16`` (the CRC over type,
length and payload, as the PUS packet error control). A receiver hunts for the sync pattern,
so a cut or a burst of noise costs the frames it touched and nothing after them; what it
skipped and what failed its CRC is counted, never raised.

OBC -> module: HEARTBEAT (``seq u16``), CONTEXT_WRITE (the OBC's context, opaque bytes),
CONTEXT_READ, TIME_READ. Module -> OBC: CONTEXT (``status u8`` then the bytes), TIME
(``status u8, day u16, ms u32``: the DS3231's UTC, CCSDS day segmented since 1958), ACK
(``type u8, status u8`` of a CONTEXT_WRITE).
"""

import struct

from obsw.compat import const
from obsw.crc import crc16_ccitt

SYNC = b"\xa5\x5a"
MAX_PAYLOAD = const(250)

T_HEARTBEAT = const(1)
T_CONTEXT_WRITE = const(2)
T_CONTEXT_READ = const(3)
T_TIME_READ = const(4)
T_CONTEXT = const(5)
T_TIME = const(6)
T_ACK = const(7)
TYPE_NAMES = ("", "heartbeat", "context_write", "context_read", "time_read", "context", "time")
TYPE_NAMES += ("ack",)

OK = const(0)
NONE = const(1)  # nothing stored / the clock has stopped
FAILED = const(2)  # the safeguard memory could not keep it


class LinkError(ValueError):
    """A frame that cannot be built: payload too long or type out of range."""

    def __init__(self, msg, frame_type=None):
        super().__init__(msg)
        self.frame_type = frame_type


def encode(frame_type, payload=b""):
    """One frame's bytes."""
    if not 0 < frame_type < 256:
        raise LinkError("frame type %r outside 1..255" % (frame_type,), frame_type)
    n = len(payload)
    if n > MAX_PAYLOAD:
        raise LinkError("payload of %d bytes, at most %d" % (n, MAX_PAYLOAD), frame_type)
    body = bytes((frame_type, n)) + bytes(payload)
    return SYNC + body + struct.pack(">H", crc16_ccitt(body))


def heartbeat(seq):
    return encode(T_HEARTBEAT, struct.pack(">H", seq & 0xFFFF))


def time_reply(status, day=0, ms=0):
    return encode(T_TIME, struct.pack(">BHI", status, day & 0xFFFF, ms))


def parse_time(payload):
    """(status, day, ms) of a TIME payload."""
    if len(payload) != 7:
        raise LinkError("TIME payload of %d bytes, needs 7" % len(payload), T_TIME)
    return struct.unpack(">BHI", payload)


class Decoder:
    """Stream decoder: ``feed(data)`` returns the complete frames as (type, payload)."""

    def __init__(self):
        self.buf = bytearray()
        self.counters = {"frames": 0, "skipped": 0, "bad_crc": 0}

    def feed(self, data):
        buf = self.buf
        buf.extend(data)
        out = []
        while True:
            i = buf.find(SYNC)
            if i < 0:
                keep = 1 if buf and buf[-1] == SYNC[0] else 0
                self.counters["skipped"] += len(buf) - keep
                self.buf = buf = buf[len(buf) - keep :]
                break
            if i:
                self.counters["skipped"] += i
                buf = buf[i:]
            if len(buf) < 6:
                break
            n = buf[3]
            end = 6 + n
            if len(buf) < end:
                break
            body = bytes(buf[2 : 4 + n])
            if (buf[end - 2] << 8 | buf[end - 1]) != crc16_ccitt(body):
                self.counters["bad_crc"] += 1
                self.counters["skipped"] += 2
                buf = buf[2:]  # hunt for the next sync inside this one
                continue
            out.append((body[0], body[2:]))
            self.counters["frames"] += 1
            buf = buf[end:]
        self.buf = buf
        return out
