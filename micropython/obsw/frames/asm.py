"""Channel access data units: the attached sync marker 1ACFFC1D before each (randomized) frame."""

from obsw.frames.randomizer import randomize_tm

ASM = b"\x1a\xcf\xfc\x1d"


def cadu(frame, randomize=True):
    """ASM followed by the frame, TM-randomized unless ``randomize`` is false."""
    return ASM + (randomize_tm(frame) if randomize else bytes(frame))


class CaduDecoder:
    """Find fixed-length frames behind ASMs in a byte stream; ``feed`` returns frame bytes.

    Frames are derandomized but not checked (TmFrame.unpack checks the FECF). ``skipped``
    counts bytes that were not part of a CADU.
    """

    def __init__(self, frame_length, randomize=True):
        self.frame_length = frame_length
        self.randomize = randomize
        self._buf = b""
        self.frames = 0
        self.skipped = 0

    def feed(self, data):
        buf = self._buf + bytes(data)
        out = []
        pos = 0
        need = 4 + self.frame_length
        while True:
            i = buf.find(ASM, pos)
            if i < 0:
                keep = max(pos, len(buf) - 3)
                self.skipped += keep - pos
                pos = keep
                break
            self.skipped += i - pos
            pos = i
            if len(buf) - i < need:
                break
            frame = buf[i + 4 : i + need]
            out.append(randomize_tm(frame) if self.randomize else frame)
            self.frames += 1
            pos = i + need
        self._buf = buf[pos:]
        return out
