"""TM synchronization and channel coding chains of CCSDS 131.0-B: frame -> Reed-Solomon ->
pseudo-randomizer -> ASM -> convolutional code on board, and the way back on the ground."""

from obsw.frames.asm import ASM
from obsw.frames.conv import ConvEncoder
from obsw.frames.errors import FrameLengthError, RsUncorrectableError
from obsw.frames.randomizer import randomize_tm
from obsw.frames.rs import ReedSolomon

CODINGS = ("none", "rs", "conv", "concatenated")


def _check(coding):
    if coding not in CODINGS:
        raise ValueError("TM coding is one of %s, not %r" % ("|".join(CODINGS), coding))
    return coding in ("rs", "concatenated"), coding in ("conv", "concatenated")


class TmEncoder:
    """The onboard side: ``encode(frame)`` gives the channel octets of one TM frame of
    ``frame_length`` octets (the ASM and what follows it, convolutionally encoded where the
    coding says so; the code's state runs on from frame to frame)."""

    def __init__(self, frame_length, coding="none", e=16, depth=1, randomize=True):
        self.has_rs, self.has_conv = _check(coding)
        self.coding = coding
        self.frame_length = frame_length
        self.randomize = randomize
        self.rs = ReedSolomon(e, depth, frame_length) if self.has_rs else None
        self.conv = ConvEncoder() if self.has_conv else None
        self.cadu_length = self.rs.block_length + 4 if self.rs else frame_length + 4
        # octets on the channel per frame (the convolutional code doubles them)
        self.channel_length = self.cadu_length * 2 if self.conv else self.cadu_length

    def encode(self, frame):
        if len(frame) != self.frame_length:
            raise FrameLengthError("TM frame", self.frame_length, len(frame))
        block = self.rs.encode(frame) if self.rs else bytes(frame)
        cadu = ASM + (randomize_tm(block) if self.randomize else block)
        return self.conv.encode(cadu) if self.conv else cadu


class DecodedFrame:
    """A frame from the ground chain: ``data`` (None when Reed-Solomon could not correct it),
    ``corrected`` symbols per RS codeword, the ASM's bit errors, the synchronizer's state."""

    def __init__(self, data, corrected, synced, error=None):
        self.data = data
        self.corrected = corrected
        self.asm_errors = synced.asm_errors
        self.state = synced.state
        self.inverted = synced.inverted
        self.position = synced.position
        self.error = error


class SymbolCheck:
    """Channel symbols the Viterbi decoder corrected: its bits re-encoded and compared with
    the hard decisions of the symbols that went in (``errors``, of ``symbols`` compared). Only
    symbols decoded while the frame synchronizer holds lock count (without lock the symbol
    pairing may be wrong); after a realignment the symbols in flight are forgotten and the
    first K-1 bits are not counted."""

    def __init__(self):
        from obsw.frames.conv import branch_symbols

        self._branch = branch_symbols
        self.errors = 0
        self.symbols = 0
        self._hard = bytearray()
        self._state = 0
        self._warmup = 0
        self._skip = False

    def feed(self, soft, bits):
        h = self._hard
        start = 1 if self._skip and len(soft) else 0
        if start:
            self._skip = False
        for i in range(start, len(soft)):
            h.append(1 if soft[i] > 0 else 0)
        branch = self._branch
        st = self._state
        e = 0
        k = 0
        for b in bits:
            if k + 1 >= len(h):
                break
            if self._warmup:
                self._warmup -= 1
            else:
                c1, c2 = branch(st, b)
                e += (c1 != h[k]) + (c2 != h[k + 1])
                self.symbols += 2
            st = ((st << 1) | b) & 0x3F
            k += 2
        self._state = st
        self._hard = h[k:]
        self.errors += e

    def realign(self, skipping):
        self._hard = bytearray()
        self._skip = skipping
        self._warmup = 6


class TmDecoder:
    """The ground side: ``feed_bits`` (hard bits, one per octet), ``feed_octets`` (hard
    octets) or ``feed_soft`` (soft symbols, positive means 1) give DecodedFrames.

    Counters: ``frames``, ``corrected`` (RS symbols), ``uncorrectable`` (codeblocks), with
    ``count_symbols`` ``symbol_errors`` (channel symbols the Viterbi decoder corrected, see
    ``SymbolCheck``; 0 without the convolutional code), and the synchronizer's (``sync.locks``,
    ``sync.losses``, ``sync.slips``). With the convolutional code, a stream that finds no lock
    within ``realign`` CADUs is shifted by one symbol (the pair alignment of a stream joined in
    the middle is unknown)."""

    def __init__(self, frame_length, coding="none", e=16, depth=1, randomize=True,
                 sync=None, realign=3, count_symbols=False):  # fmt: skip
        from obsw.frames.sync import FrameSync

        self.has_rs, self.has_conv = _check(coding)
        self.coding = coding
        self.frame_length = frame_length
        self.randomize = randomize
        self.rs = ReedSolomon(e, depth, frame_length) if self.has_rs else None
        length = self.rs.block_length if self.rs else frame_length
        self.sync = sync if sync is not None else FrameSync(length)
        self.frames = 0
        self.corrected = 0
        self.uncorrectable = 0
        self.viterbi = None
        self.check = SymbolCheck() if count_symbols and self.has_conv else None
        self._realign = realign * 8 * (length + 4)
        self._unlocked = 0
        if self.has_conv:
            from obsw.frames.viterbi import Viterbi27

            self.viterbi = Viterbi27()
            self.viterbi.reset(None)

    def feed_octets(self, data):
        if self.has_conv:
            from obsw.frames.viterbi import soft_from_bits

            return self.feed_soft(soft_from_bits(data, 1))
        from obsw.frames.sync import unpack_bits

        return self.feed_bits(unpack_bits(data))

    def feed_soft(self, soft):
        if not self.has_conv:
            return self.feed_bits(bytes(1 if s > 0 else 0 for s in soft))
        bits = self.viterbi.feed(soft)
        check = self.check
        if check is not None:
            before = (check.errors, check.symbols)
            check.feed(soft, bits)
        out = self.feed_bits(bits)
        if check is not None and self.sync.state == 0:  # no lock: the pairing may be wrong
            check.errors, check.symbols = before
        if self.sync.state == 0 and not out:
            self._unlocked += len(bits)
            if self._unlocked > self._realign:
                self._unlocked = 0
                self.viterbi.realign()
                if self.check is not None:
                    self.check.realign(self.viterbi.skipping)
        else:
            self._unlocked = 0
        return out

    @property
    def symbol_errors(self):
        return self.check.errors if self.check is not None else 0

    def flush(self):
        """Decode what the Viterbi decoder and the synchronizer still hold (end of a pass)."""
        bits = self.viterbi.flush() if self.viterbi is not None else b""
        if self.check is not None:
            self.check.feed((), bits)
        out = self.feed_bits(bits) if self.viterbi is not None else []
        return out + self._frames(self.sync.flush())

    def feed_bits(self, bits):
        return self._frames(self.sync.feed(bits))

    def _frames(self, synced_frames):
        out = []
        for synced in synced_frames:
            block = randomize_tm(synced.data) if self.randomize else synced.data
            corrected = []
            error = None
            data = block
            if self.rs is not None:
                try:
                    data, corrected = self.rs.decode(block)
                    self.corrected += sum(corrected)
                except RsUncorrectableError as e:
                    error = e
                    corrected = e.corrected
                    data = None
                    self.uncorrectable += 1
            self.frames += 1
            out.append(DecodedFrame(data, corrected, synced, error))
        return out
