"""PUS message structures: struct runs, repeated groups, nested groups and deduced fields."""

import struct
import unittest

from obsw.bits import BitsTooShortError, Decoder, Encoder
from obsw.pus.fields import FieldTypeError, FieldValueError, field
from obsw.pus.structure import Deduced, Repeated, Structure

U8 = field(3, 4)
U16 = field(3, 12)
U32 = field(3, 14)
F32 = field(5, 1)

# ST[20] parameter values: the parameter ID says which type the value has (PTC 11)
PARAMS = {1: U8, 2: (4, 12), 3: F32, 4: (8, 0), 5: (1, 0)}


class TestStructure(unittest.TestCase):
    def test_housekeeping_report_matches_struct(self):
        # TM[3,25]: structure ID then 16 uint32 values, packed with one struct call
        s = Structure([("sid", U16)] + [("p%d" % i, U32) for i in range(16)])
        values = {"sid": 7}
        for i in range(16):
            values["p%d" % i] = i * 1000003
        data = s.pack(values)
        self.assertEqual(data, struct.pack(">H16I", 7, *[i * 1000003 for i in range(16)]))
        self.assertEqual(s.unpack(data), values)
        self.assertEqual(s.min_bits, 8 * 66)

    def test_struct_only_structure_errors(self):
        s = Structure([("a", U16), ("b", U32), ("c", F32)])
        self.assertEqual(s.pack({"a": 1, "b": 2, "c": 0.5}), bytes.fromhex("0001000000023f000000"))
        with self.assertRaises(FieldValueError) as cm:
            s.pack({"a": 1, "b": -2, "c": 0.5})
        self.assertTrue(str(cm.exception).startswith("b "))
        with self.assertRaises(FieldValueError):
            s.pack({"a": 1, "b": 2})
        with self.assertRaises(FieldValueError):
            s.pack({"a": 1, "b": 2, "c": "x"})
        with self.assertRaises(BitsTooShortError):
            s.unpack(b"\x00\x01")

    def test_mixed_bit_fields(self):
        s = Structure(
            [
                ("flag", field(1, 0)),
                ("mode", field(2, 3)),
                ("count", U16),
                ("temp", field(4, 12)),
                ("name", field(8, 0, length_bits=8)),
            ]
        )
        v = {"flag": True, "mode": 6, "count": 513, "temp": -40, "name": "eps"}
        data = s.pack(v)
        self.assertEqual(data, bytes.fromhex("e0201ffd8036570730"))
        self.assertEqual(s.unpack(data), v)

    def test_errors_name_the_field(self):
        s = Structure([("a", U8), ("b", U16), ("c", field(2, 3))])
        with self.assertRaises(FieldValueError) as cm:
            s.pack({"a": 1, "b": 70000, "c": 1})
        self.assertIn("b ", str(cm.exception))
        self.assertIn("0..65535", str(cm.exception))
        with self.assertRaises(FieldValueError) as cm:
            s.pack({"a": 1, "b": 2, "c": 9})
        self.assertTrue(str(cm.exception).startswith("c "))
        with self.assertRaises(FieldValueError) as cm:
            s.pack({"a": 1, "b": 2})
        self.assertIn("c", str(cm.exception))
        with self.assertRaises(FieldValueError):
            s.pack([1, 2, 3])

    def test_exact_and_short(self):
        s = Structure([("a", U8), ("b", U16)])
        self.assertEqual(s.unpack(b"\x01\x00\x02"), {"a": 1, "b": 2})
        with self.assertRaises(FieldValueError):
            s.unpack(b"\x01\x00\x02\x00")
        self.assertEqual(s.unpack(b"\x01\x00\x02\x00", exact=False), {"a": 1, "b": 2})
        with self.assertRaises(BitsTooShortError):
            s.unpack(b"\x01\x00")

    def test_bad_definition(self):
        with self.assertRaises(FieldTypeError):
            Structure([("a", 3)])


class TestRepeated(unittest.TestCase):
    def test_list_of_ids(self):
        # TC[20,1]: N then N parameter IDs
        s = Structure([("ids", Repeated(U16, U16))])
        self.assertEqual(s.pack({"ids": [1, 2, 0xFFFF]}), bytes.fromhex("000300010002ffff"))
        self.assertEqual(s.unpack(bytes.fromhex("00020005000a")), {"ids": [5, 10]})
        self.assertEqual(s.pack({"ids": []}), b"\x00\x00")

    def test_item_errors_name_the_index(self):
        s = Structure([("ids", Repeated(U8, U16))])
        with self.assertRaises(FieldValueError) as cm:
            s.pack({"ids": [1, -2]})
        self.assertIn("[1]", str(cm.exception))
        with self.assertRaises(FieldValueError):
            s.pack({"ids": [0] * 256})  # N does not fit its counter

    def test_nested_groups(self):
        # TC[3,1]-like: ID, interval, N1 IDs, NFA groups of (repetition, N2 IDs)
        s = Structure(
            [
                ("sid", U16),
                ("interval", U32),
                ("ids", Repeated(U16, U16)),
                ("groups", Repeated(U16, [("rep", U16), ("ids", Repeated(U16, U16))])),
            ]
        )
        v = {
            "sid": 1,
            "interval": 10,
            "ids": [3, 4],
            "groups": [{"rep": 2, "ids": [5]}, {"rep": 8, "ids": []}],
        }
        data = s.pack(v)
        self.assertEqual(data.hex(), "00010000000a000200030004000200020001000500080000")
        self.assertEqual(s.unpack(data), v)

    def test_bit_items(self):
        s = Structure([("flags", Repeated(field(3, 0), field(1, 0)))])
        data = s.pack({"flags": [True, False, True]})
        self.assertEqual(data, bytes([0x3A]))
        self.assertEqual(s.unpack(data), {"flags": [True, False, True]})

    def test_huge_count_fails_fast(self):
        s = Structure([("ids", Repeated(U32, U16))])
        with self.assertRaises(BitsTooShortError):
            s.unpack(b"\xff\xff\xff\xff\x00\x01")

    def test_standalone(self):
        r = Repeated(U8, F32)
        e = Encoder()
        r.write(e, [0.5, -1.0])
        self.assertEqual(r.read(Decoder(e.getvalue())), [0.5, -1.0])


class TestDeduced(unittest.TestCase):
    def test_parameter_values(self):
        # TC[20,3]: N then (parameter ID, value of the type that ID has)
        s = Structure(
            [
                (
                    "params",
                    Repeated(U8, [("id", U16), ("value", field(11, 0, key="id", lookup=PARAMS))]),
                )
            ]
        )
        v = {
            "params": [
                {"id": 1, "value": 200},
                {"id": 2, "value": -2},
                {"id": 3, "value": 0.5},
                {"id": 4, "value": "ok"},
                {"id": 5, "value": True},
            ]
        }
        data = s.pack(v)
        self.assertEqual(data.hex(), "050001c80002fffe00033f000000000400026f6b000580")
        self.assertEqual(s.unpack(data), v)

    def test_callable_lookup_and_outer_key(self):
        def lookup(kind):
            return (3, 4) if kind == 0 else (3, 12)

        s = Structure(
            [("kind", U8), ("vals", Repeated(U8, field(11, 0, key="kind", lookup=lookup)))]
        )
        s2 = Structure([("kind", U8), ("vals", Repeated(U8, [("v", Deduced("kind", lookup))]))])
        self.assertEqual(s.pack({"kind": 1, "vals": []}), b"\x01\x00")
        data = s2.pack({"kind": 1, "vals": [{"v": 513}]})
        self.assertEqual(data, b"\x01\x01\x02\x01")
        self.assertEqual(s2.unpack(data), {"kind": 1, "vals": [{"v": 513}]})

    def test_unknown_selector(self):
        s = Structure([("id", U16), ("value", field(11, 0, key="id", lookup=PARAMS))])
        with self.assertRaises(FieldValueError):
            s.pack({"id": 99, "value": 1})
        with self.assertRaises(FieldValueError):
            s.unpack(b"\x00\x63\x00")

    def test_standalone(self):
        d = field(11, 0, lookup=PARAMS)
        self.assertEqual(d.pack((1, 7)), b"\x07")
        self.assertEqual(d.read_for(Decoder(b"\x07"), 1), 7)
        with self.assertRaises(FieldTypeError):
            d.unpack(b"\x07")
        with self.assertRaises(FieldTypeError):
            field(11, 1, lookup=PARAMS)
        with self.assertRaises(FieldTypeError):
            field(11, 0)
