"""KISS framing (the TNC convention of SatNOGS, gr-satellites and Direwolf): frames between
FEND octets, FEND and FESC inside escaped as FESC TFEND and FESC TFESC, a command octet first
(port in the high nibble, 0 = data frame)."""

from obsw.compat import const

FEND = const(0xC0)
FESC = const(0xDB)
TFEND = const(0xDC)
TFESC = const(0xDD)
DATA = const(0)


def encode(data, port=0, command=DATA):
    """One KISS frame carrying ``data`` (command ``command`` on TNC port ``port``); the
    command octet is escaped too (port 12's data frames would otherwise start with FEND)."""
    out = bytearray((FEND,))
    for b in bytes(((port << 4) | command,)) + bytes(data):
        if b == FEND:
            out.append(FESC)
            out.append(TFEND)
        elif b == FESC:
            out.append(FESC)
            out.append(TFESC)
        else:
            out.append(b)
    out.append(FEND)
    return bytes(out)


class KissDecoder:
    """Stream decoder: ``feed(data)`` returns the data frames completed, as bytes (``port``
    None: any port, else only that one). Frames of other commands, empty frames and frames
    longer than ``max_length`` are skipped and counted (``skipped``); a FESC followed by
    anything but TFEND or TFESC counts as ``bad_escapes`` and the octet is kept as it came."""

    def __init__(self, port=None, max_length=65536):
        self.port = port
        self.max_length = max_length
        self.frames = 0
        self.skipped = 0
        self.bad_escapes = 0
        self._buf = bytearray()
        self._escape = False
        self._in_frame = False  # octets before the first FEND belong to no frame

    def feed(self, data):
        out = []
        buf = self._buf
        for b in data:
            if b == FEND:
                if len(buf):
                    self._end(buf, out)
                    buf = self._buf = bytearray()
                self._in_frame = True
                self._escape = False
                continue
            if not self._in_frame:
                continue
            if self._escape:
                self._escape = False
                if b == TFEND:
                    b = FEND
                elif b == TFESC:
                    b = FESC
                else:
                    self.bad_escapes += 1
            elif b == FESC:
                self._escape = True
                continue
            if len(buf) <= self.max_length + 1:  # command octet and one octet too many at most
                buf.append(b)
        return out

    def _end(self, buf, out):
        command = buf[0]
        if (
            command & 0x0F != DATA
            or len(buf) < 2
            or len(buf) - 1 > self.max_length
            or (self.port is not None and command >> 4 != self.port)
        ):
            self.skipped += 1
            return
        self.frames += 1
        out.append(bytes(buf[1:]))
