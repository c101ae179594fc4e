"""The Communications Link Control Word (CCSDS 232.0-B 4.2), carried in the TM frame's OCF."""

from obsw.frames.errors import FrameHeaderError, FrameTooShortError

COP_1 = 1


class Clcw:
    """CLCW fields; ``report`` is N(R), the FARM's V(R)."""

    def __init__(
        self,
        vcid=0,
        report=0,
        lockout=False,
        wait=False,
        retransmit=False,
        farm_b=0,
        status=0,
        cop=COP_1,
        no_rf=False,
        no_bitlock=False,
        version=0,
    ):
        self.vcid = vcid
        self.report = report
        self.lockout = bool(lockout)
        self.wait = bool(wait)
        self.retransmit = bool(retransmit)
        self.farm_b = farm_b & 3
        self.status = status
        self.cop = cop
        self.no_rf = bool(no_rf)
        self.no_bitlock = bool(no_bitlock)
        self.version = version

    def pack(self):
        return bytes(
            (
                (self.version & 3) << 5 | (self.status & 7) << 2 | (self.cop & 3),
                (self.vcid & 0x3F) << 2,
                (0x80 if self.no_rf else 0)
                | (0x40 if self.no_bitlock else 0)
                | (0x20 if self.lockout else 0)
                | (0x10 if self.wait else 0)
                | (0x08 if self.retransmit else 0)
                | (self.farm_b & 3) << 1,
                self.report & 0xFF,
            )
        )

    @classmethod
    def unpack(cls, buf):
        if len(buf) < 4:
            raise FrameTooShortError("CLCW", 4, len(buf))
        if buf[0] & 0x80:
            raise FrameHeaderError("control word type", 1, "0 (CLCW)")
        return cls(
            vcid=buf[1] >> 2,
            report=buf[3],
            lockout=buf[2] & 0x20,
            wait=buf[2] & 0x10,
            retransmit=buf[2] & 0x08,
            farm_b=(buf[2] >> 1) & 3,
            status=(buf[0] >> 2) & 7,
            cop=buf[0] & 3,
            no_rf=buf[2] & 0x80,
            no_bitlock=buf[2] & 0x40,
            version=(buf[0] >> 5) & 3,
        )

    def __eq__(self, other):
        return isinstance(other, Clcw) and self.pack() == other.pack()

    def __repr__(self):
        return "Clcw(vc=%d N(R)=%d%s%s%s B=%d)" % (
            self.vcid,
            self.report,
            " lockout" if self.lockout else "",
            " wait" if self.wait else "",
            " retransmit" if self.retransmit else "",
            self.farm_b,
        )
