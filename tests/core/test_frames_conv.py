"""The CCSDS rate 1/2 K=7 convolutional encoder and the soft-decision Viterbi decoder."""

import unittest

from obsw.compat import speedups
from obsw.frames import conv, viterbi


def bits_of(data):
    out = bytearray()
    for b in data:
        for i in range(7, -1, -1):
            out.append((b >> i) & 1)
    return bytes(out)


def every(seq, start, stop):
    return [seq[i] for i in range(start, stop, 2)]


def octets(bits):
    out = bytearray(len(bits) // 8)
    for i in range(len(out) * 8):
        out[i >> 3] |= bits[i] << (7 - (i & 7))
    return bytes(out)


class Lcg:
    def __init__(self, seed):
        self.x = seed

    def next(self, n):
        self.x = (self.x * 1103515245 + 12345) & 0x7FFFFFFF
        return (self.x >> 8) % n

    def data(self, n):
        return bytes(self.next(256) for _ in range(n))


def decode_all(data_symbols, fast=False, chunk=None):
    v = viterbi.Viterbi27(fast=fast)
    if chunk is None:
        return v.feed(data_symbols) + v.flush()
    out = b""
    for i in range(0, len(data_symbols), chunk):
        out += v.feed(data_symbols[i : i + chunk])
    return out + v.flush()


class TestEncoder(unittest.TestCase):
    def test_impulse_response_is_the_generators(self):
        # 131.0-B: G1 = 1111001, G2 = 1011011 (171, 133 octal), the G2 symbol inverted. One 1
        # followed by zeros gives G1 on the C1 symbols and the inverted G2 on the C2 symbols.
        sym = bits_of(conv.ConvEncoder().encode(b"\x80\x00"))
        self.assertEqual(every(sym, 0, 14), [1, 1, 1, 1, 0, 0, 1])
        self.assertEqual(every(sym, 1, 14), [0, 1, 0, 0, 1, 0, 0])
        self.assertEqual(every(sym, 14, 32), [0] * 9)
        self.assertEqual(every(sym, 15, 32), [1] * 9)

    def test_zeros_give_alternating_symbols(self):
        self.assertEqual(conv.ConvEncoder().encode(bytes(4)), b"\x55" * 8)

    def test_stream_continues_across_calls(self):
        data = Lcg(1).data(50)
        enc = conv.ConvEncoder()
        self.assertEqual(enc.encode(data[:17]) + enc.encode(data[17:]),
                         conv.ConvEncoder().encode(data))  # fmt: skip

    def test_linear_tables_agree_with_the_register(self):
        rnd = Lcg(2)
        for _ in range(40):
            state, byte = rnd.next(64), rnd.next(256)
            want = 0
            s = state
            for i in range(7, -1, -1):
                b = (byte >> i) & 1
                c1, c2 = conv.branch_symbols(s, b)
                want = (want << 2) | (c1 << 1) | c2
                s = ((s << 1) | b) & 0x3F
            self.assertEqual(conv.ConvEncoder(state).encode(bytes([byte])),
                             bytes([want >> 8, want & 0xFF]))  # fmt: skip

    def test_inverted_input_gives_inverted_symbols(self):
        # G1 and G2 have five taps each: the code is transparent, so BPSK's 180-degree
        # ambiguity gives the inverted data, which the frame synchronizer detects at the ASM.
        data = Lcg(3).data(20)
        a = conv.ConvEncoder().encode(data)
        b = conv.ConvEncoder(0x3F).encode(bytes(x ^ 0xFF for x in data))
        self.assertEqual(bytes(x ^ 0xFF for x in a), b)


class TestViterbi(unittest.TestCase):
    def test_clean_round_trip_any_chunking(self):
        data = Lcg(4).data(60)
        soft = viterbi.soft_from_bits(conv.ConvEncoder().encode(data))
        for chunk in (None, 1, 7, 100):
            self.assertEqual(octets(decode_all(soft, chunk=chunk)), data)

    def test_hard_errors_corrected(self):
        # free distance 10: isolated error pairs far apart are always corrected
        data = Lcg(5).data(80)
        soft = viterbi.soft_from_bits(conv.ConvEncoder().encode(data), 1)
        for i in range(20, len(soft) - 40, 45):
            soft[i] = -soft[i]
            soft[i + 3] = -soft[i + 3]
        self.assertEqual(octets(decode_all(soft)), data)

    def test_soft_weak_wrong_symbols_outvoted(self):
        data = Lcg(6).data(40)
        soft = viterbi.soft_from_bits(conv.ConvEncoder().encode(data), 100)
        for i in range(0, len(soft), 5):
            soft[i] = -10 if soft[i] > 0 else 10  # wrong but unsure
        self.assertEqual(octets(decode_all(soft)), data)

    def test_floats(self):
        data = Lcg(7).data(16)
        soft = [0.5 * s for s in viterbi.soft_from_bits(conv.ConvEncoder().encode(data), 1)]
        self.assertEqual(octets(decode_all(soft)), data)

    def test_traceback_holds_bits_back(self):
        v = viterbi.Viterbi27(traceback=40, fast=False)
        soft = viterbi.soft_from_bits(conv.ConvEncoder().encode(bytes(100)))
        first = v.feed(soft[: 2 * 8 * 20])
        self.assertEqual(len(first), 8 * 20 - 40)
        self.assertEqual(len(first) + len(v.feed(soft[320:]) + v.flush()), 800)
        self.assertEqual(v.bits_out, 800)

    def test_odd_symbol_waits_for_its_pair(self):
        data = Lcg(8).data(30)
        soft = viterbi.soft_from_bits(conv.ConvEncoder().encode(data))
        v = viterbi.Viterbi27(fast=False)
        out = v.feed(soft[:101]) + v.feed(soft[101:]) + v.flush()
        self.assertEqual(octets(out), data)

    @unittest.skipIf(
        speedups() is None or not hasattr(speedups(), "viterbi27"),
        "no C decoder here (MicroPython, OBSW_PURE or obsw_speedups not built)",
    )
    def test_c_and_python_agree(self):
        from array import array

        rnd = Lcg(9)
        data = rnd.data(300)
        soft = viterbi.soft_from_bits(conv.ConvEncoder().encode(data), 40)
        noisy = array("b", [max(-127, min(127, s + rnd.next(161) - 80)) for s in soft])
        self.assertEqual(decode_all(noisy, True, 999), decode_all(list(noisy), False, 999))


if __name__ == "__main__":
    unittest.main()
