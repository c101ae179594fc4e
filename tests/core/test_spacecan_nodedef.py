"""SpaceCAN node definitions (spacecan's JSON) and the data layouts of the services."""

import json
import unittest

from obsw.spacecan import packets as pk
from obsw.spacecan.nodedef import NodeDefinition, NodeDefinitionError

NODE = {
    "parameters": [
        {"parameter_id": 1, "parameter_name": "mode", "encoding": "u8", "value": 3},
        {"parameter_id": 2, "parameter_name": "volt", "encoding": "f32", "value": 7.5},
        {"parameter_id": 3, "parameter_name": "count", "encoding": "u32", "value": 0x12345678},
        {"parameter_id": 4, "parameter_name": "temp", "encoding": "i16", "value": -20},
        {
            "parameter_id": 5,
            "parameter_name": "on",
            "encoding": "bool",
            "value": True,
            "unit": "x",
        },
    ],
    "housekeeping_reports": [
        {"report_id": 1, "interval": 1, "enabled": False, "parameter_ids": [1, 4]},
    ],
    "functions": [
        {
            "function_id": 1,
            "function_name": "set_line",
            "arguments": [
                {"argument_id": 1, "argument_name": "line", "encoding": "u8"},
                {"argument_id": 2, "argument_name": "level", "encoding": "i16"},
            ],
        },
        {"function_id": 2, "function_name": "reset"},
    ],
}


def h(s):
    return bytes.fromhex(s)


class TestNodeDefinition(unittest.TestCase):
    def test_load(self):
        d = NodeDefinition.from_json(json.dumps(NODE), node_id=4)
        self.assertEqual(d.node_id, 4)
        self.assertEqual(sorted(d.parameters), [1, 2, 3, 4, 5])
        self.assertEqual(d.parameter("temp").parameter_id, 4)
        self.assertEqual(d.reports[1].parameter_ids, [1, 4])
        self.assertEqual(sorted(d.functions[1].arguments), [1, 2])
        self.assertEqual(d.functions[2].arguments, {})
        self.assertEqual(d.function_by_name("reset").function_id, 2)

    def test_round_trip(self):
        d = NodeDefinition.from_dict(NODE)
        again = NodeDefinition.from_json(d.to_json())
        self.assertEqual(again.to_dict(), d.to_dict())

    def test_lists_required(self):
        for key in ("parameters", "housekeeping_reports", "functions"):
            broken = dict(NODE)
            del broken[key]
            with self.assertRaises(NodeDefinitionError) as cm:
                NodeDefinition.from_dict(broken)
            self.assertEqual(cm.exception.key, key)

    def test_invalid_entries(self):
        def variant(**kw):
            d = json.loads(json.dumps(NODE))
            for k in kw:
                d[k] = kw[k]
            return d

        bad = [
            variant(parameters=NODE["parameters"] + [NODE["parameters"][0]]),
            variant(parameters=[{"parameter_id": 1, "parameter_name": "x", "encoding": "u9"}]),
            variant(parameters=[{"parameter_id": 256, "parameter_name": "x", "encoding": "u8"}]),
            variant(parameters=[{"parameter_id": 1, "encoding": "u8", "value": 300}]),
            variant(housekeeping_reports=[{"report_id": 1, "interval": 1, "parameter_ids": [9]}]),
            variant(housekeeping_reports=[{"report_id": 1, "interval": "x", "parameter_ids": []}]),
            variant(functions=[{"function_name": "f"}]),
            variant(
                functions=[
                    {
                        "function_id": 1,
                        "arguments": [
                            {"argument_id": 1, "encoding": "u8"},
                            {"argument_id": 1, "encoding": "u8"},
                        ],
                    }
                ]
            ),
            variant(parameters={}),
        ]
        for d in bad:
            with self.assertRaises(NodeDefinitionError):
                NodeDefinition.from_dict(d)


class TestPayloads(unittest.TestCase):
    def setUp(self):
        self.d = NodeDefinition.from_dict(NODE)

    def test_service_packet(self):
        p = pk.ServicePacket(17, 1)
        self.assertEqual(p.pack(), h("1101"))
        self.assertEqual(
            pk.ServicePacket.unpack(h("14020401")), pk.ServicePacket(20, 2, h("0401"))
        )
        with self.assertRaises(pk.ServicePacketError):
            pk.ServicePacket.unpack(h("11"))

    def test_ids(self):
        self.assertEqual(pk.pack_ids([1, 2, 3, 4]), h("0401020304"))
        self.assertEqual(pk.unpack_ids(h("020109")), [1, 9])
        for bad in (b"", h("0301"), h("00aa")):
            with self.assertRaises(pk.ServicePacketError):
                pk.unpack_ids(bad)
        with self.assertRaises(pk.ServicePacketError):
            pk.pack_ids([256])

    def test_parameter_report_from_trace(self):
        data = h("0401030240f000000312345678" + "04ffec")
        self.assertEqual(
            pk.pack_values(self.d, [(1, 3), (2, 7.5), (3, 0x12345678), (4, -20)]), data
        )
        self.assertEqual(
            pk.unpack_values(self.d, data), [(1, 3), (2, 7.5), (3, 0x12345678), (4, -20)]
        )

    def test_parameter_report_errors(self):
        for bad in (b"", h("0109"), h("02010304"), h("0104ff"), h("030103")):
            with self.assertRaises(pk.ServicePacketError):
                pk.unpack_values(self.d, bad)

    def test_hk_report_from_trace(self):
        self.assertEqual(pk.pack_hk(self.d, 1), h("0103ffec"))
        self.assertEqual(pk.unpack_hk(self.d, h("0103ffec")), (1, [(1, 3), (4, -20)]))
        for bad in (b"", h("0203ffec"), h("0103ff"), h("0103ffec00")):
            with self.assertRaises(pk.ServicePacketError):
                pk.unpack_hk(self.d, bad)

    def test_function_call(self):
        self.assertEqual(pk.pack_function(self.d, 2), h("02"))
        data = pk.pack_function(self.d, 1, {2: -20, 1: 1})
        self.assertEqual(data, h("0102" + "0101" + "02ffec"))
        self.assertEqual(pk.unpack_function(self.d, data), (1, {1: 1, 2: -20}))
        self.assertEqual(pk.unpack_function(self.d, h("02")), (2, {}))
        self.assertEqual(pk.unpack_function(self.d, h("0200")), (2, {}))

    def test_function_call_errors(self):
        for bad in (
            b"",
            h("09"),
            h("01"),
            h("010101"),
            h("0102010102ff"),
            h("0103010102ffec"),
            h("01020101" + "0101"),
            h("0102010103ffec"),
        ):
            with self.assertRaises(pk.ServicePacketError):
                pk.unpack_function(self.d, bad)
        with self.assertRaises(pk.ServicePacketError):
            pk.pack_function(self.d, 1, {7: 1})
