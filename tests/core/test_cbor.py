"""CBOR codec: RFC 8949 appendix A vectors, deterministic encoding and malformed input."""

import struct
import unittest

from obsw.cbor import (
    UNDEFINED,
    CborDecodeError,
    CborEncodeError,
    Simple,
    Tag,
    decode_from,
    dumps,
    loads,
)


def h(s):
    return bytes.fromhex(s)


# (value, encoding) pairs from RFC 8949 appendix A that are also deterministic encodings
VECTORS = [
    (0, "00"),
    (1, "01"),
    (10, "0a"),
    (23, "17"),
    (24, "1818"),
    (25, "1819"),
    (100, "1864"),
    (1000, "1903e8"),
    (1000000, "1a000f4240"),
    (1000000000000, "1b000000e8d4a51000"),
    (18446744073709551615, "1bffffffffffffffff"),
    (18446744073709551616, "c249010000000000000000"),
    (-18446744073709551616, "3bffffffffffffffff"),
    (-18446744073709551617, "c349010000000000000000"),
    (-1, "20"),
    (-10, "29"),
    (-100, "3863"),
    (-1000, "3903e7"),
    (0.0, "f90000"),
    (-0.0, "f98000"),
    (1.0, "f93c00"),
    (1.1, "fb3ff199999999999a"),
    (1.5, "f93e00"),
    (65504.0, "f97bff"),
    (100000.0, "fa47c35000"),
    # the largest float32, built from its bits: a board's decimal parser (software pow) can
    # read the literal 3.4028234663852886e38 one unit in the last place away
    (struct.unpack(">f", b"\x7f\x7f\xff\xff")[0], "fa7f7fffff"),
    (1.0e300, "fb7e37e43c8800759c"),
    (5.960464477539063e-8, "f90001"),
    (0.00006103515625, "f90400"),
    (-4.0, "f9c400"),
    (-4.1, "fbc010666666666666"),
    (float("inf"), "f97c00"),
    (float("-inf"), "f9fc00"),
    (False, "f4"),
    (True, "f5"),
    (None, "f6"),
    (UNDEFINED, "f7"),
    (Simple(16), "f0"),
    (Simple(255), "f8ff"),
    (Tag(1, 1363896240), "c11a514b67b0"),
    (Tag(32, "http://www.example.com"), "d82076687474703a2f2f7777772e6578616d706c652e636f6d"),
    (b"", "40"),
    (b"\x01\x02\x03\x04", "4401020304"),
    ("", "60"),
    ("a", "6161"),
    ("IETF", "6449455446"),
    ('"\\', "62225c"),
    ("\u00fc", "62c3bc"),
    ("\u6c34", "63e6b0b4"),
    ([], "80"),
    ([1, 2, 3], "83010203"),
    ([1, [2, 3], [4, 5]], "8301820203820405"),
    (list(range(1, 26)), "98190102030405060708090a0b0c0d0e0f101112131415161718181819"),
    ({}, "a0"),
    ({1: 2, 3: 4}, "a201020304"),
    ({"a": 1, "b": [2, 3]}, "a26161016162820203"),
    (["a", {"b": "c"}], "826161a161626163"),
    (
        {"a": "A", "b": "B", "c": "C", "d": "D", "e": "E"},
        "a56161614161626142616361436164614461656145",
    ),
]


class TestVectors(unittest.TestCase):
    def test_encode_vectors(self):
        for value, enc in VECTORS:
            self.assertEqual(dumps(value), h(enc), "encoding %r" % (value,))

    def test_decode_vectors(self):
        for value, enc in VECTORS:
            self.assertEqual(loads(h(enc)), value, "decoding %s" % enc)

    def test_nan(self):
        self.assertEqual(dumps(float("nan")), h("f97e00"))
        for enc in ("f97e00", "fa7fc00000", "fb7ff8000000000000"):
            v = loads(h(enc))
            self.assertTrue(v != v)

    def test_wider_floats_decode(self):
        self.assertEqual(loads(h("fa47c35000")), 100000.0)
        self.assertEqual(loads(h("fb3ff8000000000000")), 1.5)
        self.assertEqual(loads(h("f97c00")), float("inf"))

    def test_indefinite_lengths(self):
        self.assertEqual(loads(h("5f42010243030405ff")), b"\x01\x02\x03\x04\x05")
        self.assertEqual(loads(h("7f657374726561646d696e67ff")), "streaming")
        self.assertEqual(loads(h("9fff")), [])
        self.assertEqual(loads(h("9f018202039f0405ffff")), [1, [2, 3], [4, 5]])
        self.assertEqual(loads(h("83018202039f0405ff")), [1, [2, 3], [4, 5]])
        self.assertEqual(loads(h("bf61610161629f0203ffff")), {"a": 1, "b": [2, 3]})
        self.assertEqual(loads(h("826161bf61626163ff")), ["a", {"b": "c"}])


class TestDeterministic(unittest.TestCase):
    def test_map_keys_sorted_length_first(self):
        # RFC 8949 4.2.3: shorter encoded key first, then bytewise
        self.assertEqual(dumps({24: 1, -1: 2}), h("a22002181801"))
        self.assertEqual(dumps({"aa": 1, "b": 2}), h("a261620262616101"))
        a = {}
        b = {}
        keys = [100, "x", b"k", -5, 1, (1, 2), False]
        for k in keys:
            a[k] = 0
        for k in reversed(keys):
            b[k] = 0
        self.assertEqual(dumps(a), dumps(b))

    def test_int_keys_and_bytes_survive(self):
        msg = {1: b"\x00\xff", 2: {3: [b"", -7]}, "s": 1.5}
        self.assertEqual(loads(dumps(msg)), msg)

    def test_tuple_encodes_as_array(self):
        self.assertEqual(dumps((1, 2)), dumps([1, 2]))
        self.assertEqual(loads(dumps({(1, 2): "t"})), {(1, 2): "t"})

    def test_bytearray_and_memoryview(self):
        self.assertEqual(dumps(bytearray(b"ab")), h("426162"))
        self.assertEqual(dumps(memoryview(b"abc")[1:]), h("426263"))

    def test_shortest_float(self):
        self.assertEqual(len(dumps(0.5)), 3)
        self.assertEqual(len(dumps(0.1)), 9)
        self.assertEqual(len(dumps(16777216.0)), 5)

    def test_bignums_round_trip(self):
        for v in (2**64, 2**64 + 1, 2**200, -(2**64) - 1, -(2**130)):
            self.assertEqual(loads(dumps(v)), v)
        self.assertEqual(loads(h("c240")), 0)
        self.assertEqual(loads(h("c340")), -1)

    def test_decode_from_offset(self):
        data = h("0102") + dumps([1, "x"])
        self.assertEqual(decode_from(data, 2), ([1, "x"], len(data)))
        self.assertEqual(decode_from(data, 0), (1, 1))


class TestEncodeErrors(unittest.TestCase):
    def test_unsupported_type(self):
        with self.assertRaises(CborEncodeError):
            dumps(object())
        with self.assertRaises(TypeError):
            dumps({1: [object()]})

    def test_nesting_limit(self):
        deep = []
        for _ in range(40):
            deep = [deep]
        with self.assertRaises(CborEncodeError):
            dumps(deep)
        self.assertEqual(loads(dumps(deep, max_depth=64), max_depth=64), deep)

    def test_self_reference(self):
        a = []
        a.append(a)
        with self.assertRaises(CborEncodeError):
            dumps(a)

    def test_bad_tag_and_simple(self):
        with self.assertRaises(ValueError):
            Tag(-1, 0)
        with self.assertRaises(ValueError):
            Simple(24)


class TestMalformed(unittest.TestCase):
    def bad(self, hexdata, word=None):
        with self.assertRaises(CborDecodeError) as cm:
            loads(h(hexdata))
        if word is not None:
            self.assertIn(word, str(cm.exception))
        return cm.exception

    def test_truncated(self):
        self.bad("", "truncated")
        self.bad("18", "truncated")
        self.bad("19 01".replace(" ", ""), "truncated")
        self.bad("1b00000000", "truncated")
        self.bad("62 61".replace(" ", ""), "truncated")
        self.bad("82 01".replace(" ", ""), "truncated")
        self.bad("a1 01".replace(" ", ""), "truncated")
        self.bad("fa0000", "truncated")
        self.bad("9f01", "truncated")
        self.bad("5f41", "truncated")

    def test_huge_declared_length_is_refused_before_allocating(self):
        e = self.bad("9bffffffffffffffff", "truncated")
        self.assertEqual(e.offset, 9)
        self.bad("5affffffff00", "truncated")

    def test_reserved_additional_info(self):
        for ib in ("1c", "1d", "1e", "3c", "5c", "7c", "9c", "bc", "dc", "fc", "fd", "fe"):
            self.bad(ib, "reserved")

    def test_indefinite_not_allowed(self):
        self.bad("1f", "additional info 31")
        self.bad("3f", "additional info 31")
        self.bad("df00", "additional info 31")

    def test_stray_break(self):
        self.bad("ff", "break")
        self.bad("8201ff", "break")
        self.bad("a1ff", None)
        self.bad("bf01ff", "map value")

    def test_wrong_chunks(self):
        self.bad("5f6161ff", "wrong type")
        self.bad("7f4161ff", "wrong type")
        self.bad("5f5f4100ffff", "wrong type")

    def test_invalid_utf8(self):
        self.bad("62c328", "UTF-8")
        self.bad("61ff", "UTF-8")

    def test_two_byte_simple_below_32(self):
        self.bad("f818", "one-byte")

    def test_bignum_needs_bytes(self):
        self.bad("c201", "bignum")

    def test_unhashable_key(self):
        self.bad("a1a0 01".replace(" ", ""), "map key")

    def test_trailing_bytes(self):
        e = self.bad("0000", "trailing")
        self.assertEqual(e.offset, 1)

    def test_nesting_too_deep(self):
        self.bad("81" * 40 + "00", "nesting")
        self.bad("9f" * 40, "nesting")
        self.bad("c1" * 40 + "00", "nesting")
        self.assertEqual(loads(h("81" * 10 + "00")), [[[[[[[[[[0]]]]]]]]]])

    def test_error_is_value_error(self):
        e = self.bad("18")
        self.assertIsInstance(e, ValueError)


if __name__ == "__main__":
    unittest.main()
