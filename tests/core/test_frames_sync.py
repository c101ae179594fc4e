"""Frame synchronization (131.0-B) and the TM coding chains: ASM errors, slips, polarity, lock."""

import unittest
from array import array

from obsw.frames import sync, tm_coding
from obsw.frames.asm import ASM


class Lcg:
    def __init__(self, seed):
        self.x = seed

    def next(self, n):
        self.x = (self.x * 1103515245 + 12345) & 0x7FFFFFFF
        return (self.x >> 8) % n

    def data(self, n):
        return bytes(self.next(256) for _ in range(n))


LEN = 20


def stream(frames, junk=b"\x00\x13"):
    return sync.unpack_bits(junk + b"".join(ASM + f for f in frames))


def flip(bits, positions):
    b = bytearray(bits)
    for p in positions:
        b[p] ^= 1
    return bytes(b)


def frames_of(n, seed=1):
    rnd = Lcg(seed)
    # frame data free of anything ASM-like: the synchronizer must not lock inside a frame
    return [bytes(0x55 ^ (rnd.next(2) << 1) for _ in range(LEN)) for _ in range(n)]


class TestBits(unittest.TestCase):
    def test_pack_unpack(self):
        data = Lcg(1).data(33)
        bits = sync.unpack_bits(data)
        self.assertEqual(len(bits), 264)
        self.assertEqual(sync.pack_bits(bits), data)
        self.assertEqual(sync.pack_bits(bits, True), bytes(b ^ 0xFF for b in data))
        self.assertEqual(sync.unpack_bits(b"\xa0"), b"\x01\x00\x01\x00\x00\x00\x00\x00")


class TestSearch(unittest.TestCase):
    def test_clean_stream_locks_and_gives_every_frame(self):
        frames = frames_of(5)
        fs = sync.FrameSync(LEN)
        got = fs.feed(stream(frames)) + fs.flush()
        self.assertEqual([g.data for g in got], frames)
        self.assertEqual(fs.locks, 1)
        self.assertEqual(fs.skipped, 16)
        self.assertEqual([g.state for g in got][:2], [sync.VERIFY, sync.LOCK])
        self.assertEqual(fs.take_events(), [("lock", 16 + 8 * (LEN + 4))])

    def test_search_tolerance_edge(self):
        frames = frames_of(3)
        for errors in (2, 3, 4):
            bits = flip(stream(frames), range(16, 16 + errors))
            fs = sync.FrameSync(LEN, search_errors=3, verify=1)
            got = fs.feed(bits) + fs.flush()
            first = got[0].position if got else None
            self.assertEqual(first, 16 if errors <= 3 else 16 + 8 * (LEN + 4))

    def test_any_bit_offset_and_chunking(self):
        frames = frames_of(4)
        bits = b"\x01\x00\x01" + stream(frames)
        fs = sync.FrameSync(LEN)
        got = []
        for i in range(0, len(bits), 13):
            got += fs.feed(bits[i : i + 13])
        got += fs.flush()
        self.assertEqual([g.data for g in got], frames)

    def test_inverted_polarity(self):
        frames = frames_of(3)
        bits = bytes(1 - b for b in stream(frames))
        fs = sync.FrameSync(LEN)
        got = fs.feed(bits) + fs.flush()
        self.assertEqual([g.data for g in got], frames)
        self.assertTrue(got[0].inverted)
        self.assertTrue(fs.inverted)


class TestLock(unittest.TestCase):
    def test_lock_tolerance_and_flywheel_then_loss(self):
        frames = frames_of(8)
        period = 8 * (LEN + 4)
        bits = stream(frames)
        # ASMs 3 and 4 broken beyond lock_errors (7 wrong bits): flywheel, frames still come
        bad = flip(bits, list(range(16 + 3 * period, 16 + 3 * period + 7))
                   + list(range(16 + 4 * period, 16 + 4 * period + 7)))  # fmt: skip
        fs = sync.FrameSync(LEN, lock_errors=6, flywheel=3)
        got = fs.feed(bad) + fs.flush()
        self.assertEqual([g.data for g in got], frames)
        self.assertEqual([g.state for g in got][3:6], [sync.FLYWHEEL, sync.FLYWHEEL, sync.LOCK])
        self.assertEqual(fs.losses, 0)
        # six wrong bits is still lock
        fs = sync.FrameSync(LEN, lock_errors=6)
        got = fs.feed(flip(bits, range(16 + 3 * period, 16 + 3 * period + 6))) + fs.flush()
        self.assertEqual(got[3].state, sync.LOCK)
        self.assertEqual(got[3].asm_errors, 6)
        # three misses in a row: loss of lock
        broken = []
        for k in (3, 4, 5):
            broken += range(16 + k * period, 16 + k * period + 16)
        fs = sync.FrameSync(LEN, flywheel=3)
        got = fs.feed(flip(bits, broken)) + fs.flush()
        self.assertEqual(fs.losses, 1)
        self.assertEqual(fs.locks, 2)
        self.assertEqual(got[-1].data, frames[-1])

    def test_bit_slips_within_window(self):
        frames = frames_of(6)
        period = 8 * (LEN + 4)
        for slip in (-2, -1, 1, 2, 3):
            bits = stream(frames)
            at = 16 + 3 * period - 40
            if slip < 0:
                bits = bits[:at] + bits[at - slip :]
            else:
                bits = bits[:at] + bytes(slip) + bits[at:]
            fs = sync.FrameSync(LEN, slip=2)
            got = fs.feed(bytes(bits)) + fs.flush()
            datas = [g.data for g in got]
            if abs(slip) <= 2:
                self.assertEqual(fs.slips, 1)
                self.assertEqual(datas[3:], frames[3:])
                self.assertEqual(fs.losses, 0)
            else:
                self.assertEqual(fs.slips, 0)
                self.assertEqual(fs.losses, 1)
                self.assertEqual(datas[-1], frames[-1])

    def test_early_asm_found_across_a_chunk_boundary(self):
        # bits lost just before an ASM make it come early; the feed that ended where the ASM
        # was due kept the bits it needs to look back at
        frames = frames_of(6)
        period = 8 * (LEN + 4)
        for slip in (1, 2):
            bits = stream(frames)
            at = 16 + 3 * period - 8
            bits = bits[:at] + bits[at + slip :]
            for cut in range(16 + 3 * period - 4, 16 + 3 * period + 4):
                fs = sync.FrameSync(LEN, slip=2)
                got = fs.feed(bits[:cut]) + fs.feed(bits[cut:]) + fs.flush()
                self.assertEqual([g.data for g in got][3:], frames[3:])
                self.assertEqual((fs.slips, fs.losses), (1, 0))

    def test_verify_needs_consecutive_asms(self):
        frames = frames_of(4)
        fs = sync.FrameSync(LEN, verify=3)
        got = fs.feed(stream(frames)) + fs.flush()
        self.assertEqual([g.state for g in got], [1, 1, 2, 2])


class TestChains(unittest.TestCase):
    def run_chain(self, coding, bits_mangler=None, n=4, depth=2, length=60):
        rnd = Lcg(7)
        frames = [rnd.data(length) for _ in range(n)]
        enc = tm_coding.TmEncoder(length, coding, 8, depth)
        raw = b"\x12\x34" + b"".join(enc.encode(f) for f in frames)
        bits = sync.unpack_bits(raw)
        if bits_mangler:
            bits = bits_mangler(bits)
        dec = tm_coding.TmDecoder(length, coding, 8, depth)
        if dec.has_conv:
            got = dec.feed_soft(array("b", [1 if b else -1 for b in bits])) + dec.flush()
        else:
            got = dec.feed_bits(bits) + dec.flush()
        return frames, got, dec

    def test_every_coding_round_trips(self):
        for coding in tm_coding.CODINGS:
            frames, got, dec = self.run_chain(coding)
            self.assertEqual([g.data for g in got], frames)
            self.assertEqual(dec.frames, 4)

    def test_rs_corrects_and_counts(self):
        def mangle(bits):
            return flip(bits, range(400, 400 + 8 * 5, 8))  # five symbols of the first block

        frames, got, dec = self.run_chain("rs", mangle)
        self.assertEqual([g.data for g in got], frames)
        self.assertEqual(dec.corrected, 5)

    def test_concatenated_inverted_and_noisy(self):
        def mangle(bits):
            return flip(bytes(1 - b for b in bits), range(300, 2500, 97))

        frames, got, dec = self.run_chain("concatenated", mangle)
        self.assertEqual([g.data for g in got], frames)
        self.assertTrue(got[0].inverted)

    def test_uncorrectable_block_is_reported(self):
        def mangle(bits):
            return flip(bits, range(16 + 40, 16 + 40 + 8 * 40, 8))

        frames, got, dec = self.run_chain("rs", mangle, depth=1)
        self.assertIsNone(got[0].data)
        self.assertEqual(got[0].corrected, [-1])
        self.assertEqual(dec.uncorrectable, 1)
        self.assertEqual([g.data for g in got[1:]], frames[1:])

    def test_conv_stream_joined_mid_pair_realigns(self):
        rnd = Lcg(11)
        frames = [rnd.data(30) for _ in range(12)]
        enc = tm_coding.TmEncoder(30, "conv")
        bits = sync.unpack_bits(b"".join(enc.encode(f) for f in frames))[1:]  # one symbol lost
        dec = tm_coding.TmDecoder(30, "conv", realign=2)
        got = []
        for i in range(0, len(bits), 500):
            got += dec.feed_soft([1 if b else -1 for b in bits[i : i + 500]])
        got += dec.flush()
        datas = [g.data for g in got]
        self.assertEqual(datas[-4:], frames[-4:])

    def test_viterbi_corrections_counted(self):
        rnd = Lcg(5)
        frames = [rnd.data(30) for _ in range(8)]
        enc = tm_coding.TmEncoder(30, "conv")
        clean = sync.unpack_bits(b"".join(enc.encode(f) for f in frames))
        for where in ((), (100,), range(200, 2000, 61)):
            bits = flip(clean, where)
            dec = tm_coding.TmDecoder(30, "conv", count_symbols=True)
            got = []
            for i in range(0, len(bits), 300):
                got += dec.feed_soft([1 if b else -1 for b in bits[i : i + 300]])
            got += dec.flush()
            self.assertEqual([g.data for g in got], frames)
            self.assertEqual(dec.symbol_errors, len(where))
            self.assertEqual(dec.check.symbols, len(bits))
        self.assertEqual(tm_coding.TmDecoder(30, "rs", count_symbols=True).symbol_errors, 0)

    def test_viterbi_count_after_a_realignment(self):
        rnd = Lcg(11)
        frames = [rnd.data(30) for _ in range(12)]
        enc = tm_coding.TmEncoder(30, "conv")
        bits = sync.unpack_bits(b"".join(enc.encode(f) for f in frames))[1:]  # one symbol lost
        bits = flip(bits, (3001,))
        dec = tm_coding.TmDecoder(30, "conv", realign=2, count_symbols=True)
        for i in range(0, len(bits), 500):
            dec.feed_soft([1 if b else -1 for b in bits[i : i + 500]])
        dec.flush()
        self.assertEqual(dec.symbol_errors, 1)  # the flip after the realignment, nothing else

    def test_bad_coding_name(self):
        with self.assertRaises(ValueError):
            tm_coding.TmEncoder(100, "turbo")


if __name__ == "__main__":
    unittest.main()
