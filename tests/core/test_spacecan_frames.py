"""SpaceCAN identifiers, SCET/UTC frames and value encodings, against the captured 0.8.1 trace."""

import unittest

from obsw.spacecan import encoding as enc
from obsw.spacecan import ids
from obsw.spacecan.timeframes import CanFrameLengthError, FieldRangeError, ScetTime, UtcTime


def h(s):
    return bytes.fromhex(s)


class TestIds(unittest.TestCase):
    def test_allocation(self):
        self.assertEqual(ids.ID_SYNC, 0x080)
        self.assertEqual(ids.ID_SCET, 0x180)
        self.assertEqual(ids.ID_UTC, 0x200)
        self.assertEqual(ids.ID_HEARTBEAT, 0x700)
        self.assertEqual(ids.req_id(1), 0x281)
        self.assertEqual(ids.rep_id(127), 0x37F)
        self.assertEqual(ids.function_of(0x2FF), ids.ID_REQ)
        self.assertEqual(ids.node_of(0x305), 5)

    def test_node_id_range(self):
        self.assertEqual(ids.check_node_id(1), 1)
        self.assertEqual(ids.check_node_id(127), 127)
        for bad in (0, 128, -1, True, "1", None):
            with self.assertRaises(ids.NodeIdError):
                ids.check_node_id(bad)

    def test_describe(self):
        self.assertEqual(ids.describe(0x281), "REQ n1")
        self.assertEqual(ids.describe(0x301), "REP n1")
        self.assertEqual(ids.describe(0x700), "HEARTBEAT")
        self.assertEqual(ids.other_bus(ids.BUS_A), ids.BUS_B)
        self.assertEqual(ids.bus_name(1), "B")


class TestTimeFrames(unittest.TestCase):
    def test_scet_trace(self):
        t = ScetTime.unpack(h("aabbcc11223344"))
        self.assertEqual(t.fine_time, 0xAABBCC)
        self.assertEqual(t.coarse_time, 0x11223344)
        self.assertEqual(ScetTime(0x11223344, 0xAABBCC).pack(), h("aabbcc11223344"))
        self.assertAlmostEqual(ScetTime(10, 1 << 23).seconds(), 10.5)

    def test_utc_trace(self):
        t = UtcTime.unpack(h("eeffaabbccdd1122"))
        self.assertEqual((t.sub_ms, t.ms_of_day, t.day), (0xEEFF, 0xAABBCCDD, 0x1122))
        self.assertEqual(UtcTime(0x1122, 0xAABBCCDD, 0xEEFF).pack(), h("eeffaabbccdd1122"))
        self.assertEqual(UtcTime.unpack(t.pack()), t)

    def test_lengths_checked(self):
        with self.assertRaises(CanFrameLengthError) as cm:
            ScetTime.unpack(h("aabbcc112233"))
        self.assertEqual((cm.exception.expected, cm.exception.got), (7, 6))
        with self.assertRaises(CanFrameLengthError):
            UtcTime.unpack(h("eeffaabbccdd112233"))

    def test_ranges_checked(self):
        with self.assertRaises(FieldRangeError):
            ScetTime(1 << 32)
        with self.assertRaises(FieldRangeError):
            ScetTime(0, 1 << 24)
        with self.assertRaises(FieldRangeError):
            UtcTime(1 << 16, 0)
        with self.assertRaises(FieldRangeError):
            UtcTime(0, -1)


class TestEncoding(unittest.TestCase):
    def test_sizes(self):
        expect = {
            "bool": 1,
            "i8": 1,
            "u8": 1,
            "i16": 2,
            "u16": 2,
            "i32": 4,
            "u32": 4,
            "i64": 8,
            "u64": 8,
            "f32": 4,
            "f64": 8,
        }
        for name in expect:
            self.assertEqual(enc.size(name), expect[name])
        self.assertEqual(enc.size("u8,f32"), 5)

    def test_values_from_trace(self):
        self.assertEqual(enc.encode("f32", 7.5), h("40f00000"))
        self.assertEqual(enc.encode("i16", -20), h("ffec"))
        self.assertEqual(enc.encode("u32", 0x12345678), h("12345678"))
        self.assertEqual(enc.decode("i16", h("00ffec"), 1), (-20, 3))

    def test_round_trip_limits(self):
        cases = [
            ("bool", True),
            ("bool", False),
            ("i8", -128),
            ("i8", 127),
            ("u8", 255),
            ("i16", -32768),
            ("u16", 65535),
            ("i32", -(1 << 31)),
            ("u32", (1 << 32) - 1),
            ("i64", -(1 << 63)),
            ("u64", (1 << 64) - 1),
            ("f64", 0.1),
            ("f32", -2.5),
        ]
        for name, v in cases:
            b = enc.encode(name, v)
            self.assertEqual(len(b), enc.size(name))
            self.assertEqual(enc.decode(name, b)[0], v)

    def test_big_endian_signed(self):
        self.assertEqual(enc.encode("i64", -2), h("fffffffffffffffe"))
        self.assertEqual(enc.encode("u16", 0x1234), h("1234"))

    def test_list_encoding(self):
        b = enc.encode("u8,i16", (3, -20))
        self.assertEqual(b, h("03ffec"))
        self.assertEqual(enc.decode("u8,i16", b), ((3, -20), 3))

    def test_errors(self):
        for name, v in (
            ("u8", 256),
            ("u8", -1),
            ("i8", 128),
            ("u16", 1.5),
            ("bool", 2),
            ("f32", "x"),
            ("u64", 1 << 64),
        ):
            with self.assertRaises(enc.EncodingError):
                enc.encode(name, v)
        with self.assertRaises(enc.EncodingError):
            enc.size("u12")
        with self.assertRaises(enc.EncodingError):
            enc.encode("u8,u8", (1,))
        with self.assertRaises(enc.ValueTooShortError) as cm:
            enc.decode("u32", h("0102"))
        self.assertEqual((cm.exception.needed, cm.exception.got), (4, 2))
