"""ST[02] device-level commands: on/off device commands (2,1), register loads (2,2), CPDU
commands (2,4) and register dumps (2,5 -> 2,6), through the DeviceAccess component to a
SpaceCAN node with CPDU functions; unknown addresses, refusals and silent devices."""

import unittest

from obsw.il.node import Node
from obsw.pus.messages import (
    FAILURE_COMPONENT,
    FAILURE_TIMEOUT,
    FAILURE_UNAVAILABLE,
    FAILURE_UNKNOWN_ID,
)
from obsw.pus.services.s02_device_access import DeviceAccess, DeviceUser
from obsw.spacecan.controller import Controller
from obsw.spacecan.device_access import DEVICE_ACCESS, SpaceCanDeviceAccess
from obsw.spacecan.nodedef import NodeDefinition
from obsw.spacecan.responder import Responder
from obsw.spacecan.sim import SimNetwork
from pus_loop import APID, Loop, asyncio

CPDU_NODE = {
    "parameters": [
        {"parameter_id": 1, "parameter_name": "state_bits", "encoding": "u16", "value": 0},
        {"parameter_id": 2, "parameter_name": "offset", "encoding": "i8", "value": -2},
        {"parameter_id": 3, "parameter_name": "temperature", "encoding": "f32", "value": 1.5},
        {"parameter_id": 4, "parameter_name": "uptime", "encoding": "u64", "value": 0},
    ],
    "housekeeping_reports": [],
    "functions": [
        {"function_id": 2, "function_name": "set_bits",
         "arguments": [{"argument_id": 1, "argument_name": "mask", "encoding": "u16"}]},
        {"function_id": 3, "function_name": "clear_bits",
         "arguments": [{"argument_id": 1, "argument_name": "mask", "encoding": "u16"}]},
        {"function_id": 4, "function_name": "power_cycle",
         "arguments": [{"argument_id": 1, "argument_name": "line", "encoding": "u8"},
                       {"argument_id": 2, "argument_name": "off_ms", "encoding": "u16"}]},
    ],
}  # fmt: skip
CPDU = 10  # the node id
SILENT = 12  # declared, never answers
TEMPERATURE = CPDU << 16 | 3  # register addresses
OFFSET = CPDU << 16 | 2
STATE = CPDU << 16 | 1


def on(line, node=CPDU):
    return node << 8 | 0x80 | line


def off(line, node=CPDU):
    return node << 8 | line


class Bench:
    def __init__(self):
        self.controller = Controller(timeout=0.3, retries=0)
        self.controller.add_node(CPDU, NodeDefinition.from_dict(CPDU_NODE))
        self.controller.add_node(SILENT, NodeDefinition.from_dict(CPDU_NODE))
        self.access = SpaceCanDeviceAccess(self.controller, timeout=0.5)
        self.cpdu = Responder(CPDU, NodeDefinition.from_dict(CPDU_NODE))
        self.calls = []
        self.refuse = False
        self.cpdu.on_function = self._function
        self.net = SimNetwork().attach(self.access, self.cpdu)
        self.loop = Loop()
        self.node = Node("obc", clock=self.loop.clock)
        self.node.provide(DEVICE_ACCESS, self.access)
        self.loop.app.register(DeviceAccess(self.node, timeout=2.0))
        self.user = self.loop.ground.register(DeviceUser())

    def _function(self, fid, args):
        self.calls.append((fid, args))
        if self.refuse:
            return False
        state = self.cpdu.nodedef.parameters[1]
        if fid == 2:
            state.value |= args[1]
        elif fid == 3:
            state.value &= ~args[1]
        return True

    def run(self, make):
        box = []

        async def main():
            box.append(make())
            for _ in range(2000):
                self.loop.pump()
                self.node.poll()
                self.net.run(0.01)
                await asyncio.sleep(0)
                if box[0].done and not self.loop.app.tasks:
                    break
            self.loop.pump()

        asyncio.run(main())
        return box[0]

    def state(self):
        return self.cpdu.nodedef.parameters[1].value


class TestDeviceCommands(unittest.TestCase):
    def test_on_off_device_commands_set_and_clear_lines(self):
        b = Bench()
        tx = b.run(lambda: b.user.on_off(APID, [on(0), on(3), off(0)]))
        self.assertTrue(tx.ok)
        self.assertEqual(b.calls, [(2, {1: 1}), (2, {1: 8}), (3, {1: 1})])
        self.assertEqual(b.state(), 8)
        self.assertEqual(b.loop.types(), [(1, 1), (1, 3), (1, 7)])

    def test_cpdu_commands_pulse_lines(self):
        b = Bench()
        tx = b.run(lambda: b.user.cpdu(APID, [(CPDU << 8 | 2, 500), (CPDU << 8 | 5, 20)]))
        self.assertTrue(tx.ok)
        self.assertEqual(b.calls, [(4, {1: 2, 2: 500}), (4, {1: 5, 2: 20})])

    def test_register_load_and_dump(self):
        b = Bench()
        tx = b.run(lambda: b.user.dump_registers(APID, [STATE, OFFSET, TEMPERATURE]))
        self.assertTrue(tx.ok)
        # the parameters' encoded octets as unsigned integers: -2 as i8, 1.5 as f32
        self.assertEqual(
            tx.reply, {"registers": [(STATE, 0), (OFFSET, 0xFE), (TEMPERATURE, 0x3FC00000)]}
        )
        self.assertEqual(b.loop.types()[-2:], [(2, 6), (1, 7)])
        tx = b.run(
            lambda: b.user.load_registers(
                APID, {STATE: 0x1234, OFFSET: 0x85, TEMPERATURE: 0x40490FDB}
            )
        )
        self.assertTrue(tx.ok)
        params = b.cpdu.nodedef.parameters
        self.assertEqual((params[1].value, params[2].value), (0x1234, -123))
        self.assertAlmostEqual(params[3].value, 3.14159, 4)
        tx = b.run(lambda: b.user.dump_registers(APID, [STATE]))
        self.assertEqual(tx.reply["registers"], [(STATE, 0x1234)])

    def test_unknown_addresses_fail_the_start_and_send_nothing(self):
        b = Bench()
        cases = (
            (lambda: b.user.on_off(APID, [on(1), on(1, node=30)]), b"\x1e\x81"),
            (
                lambda: b.user.load_registers(APID, {STATE: 1, CPDU << 16 | 9: 1}),
                b"\x00\x0a\x00\x09",
            ),
            (lambda: b.user.dump_registers(APID, [CPDU << 16 | 4]), b"\x00\x0a\x00\x04"),  # u64
            (lambda: b.user.cpdu(APID, [(40 << 8 | 1, 10)]), b"\x28\x01"),
        )
        for make_tx, data in cases:
            tx = b.run(make_tx)
            self.assertEqual(
                (tx.failure["stage"], tx.failure["code"], tx.failure["data"]),
                (2, FAILURE_UNKNOWN_ID, data),
            )
        self.assertEqual(b.calls, [])
        self.assertEqual(b.state(), 0)

    def test_refusals_and_silence_fail_the_completion(self):
        b = Bench()
        tx = b.run(lambda: b.user.load_registers(APID, {OFFSET: 0x1FF}))  # 9 bits in an i8
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (4, FAILURE_COMPONENT))
        self.assertEqual(tx.failure["data"], b"\x00\x0a\x00\x02")
        b.refuse = True
        tx = b.run(lambda: b.user.on_off(APID, [on(1), on(2)]))
        self.assertEqual(
            (tx.failure["code"], tx.failure["data"]), (FAILURE_COMPONENT, b"\x0a\x81")
        )
        self.assertEqual(len(b.calls), 1)  # the first failed: the second never went out
        tx = b.run(lambda: b.user.cpdu(APID, [(SILENT << 8 | 1, 10)]))
        self.assertEqual((tx.failure["code"], tx.failure["data"]), (FAILURE_TIMEOUT, b"\x0c\x01"))

    def test_no_device_access_component_fails_the_start(self):
        loop = Loop()
        loop.app.register(DeviceAccess(Node("alone", clock=loop.clock), timeout=0.05))
        user = loop.ground.register(DeviceUser())
        tx = loop.run_async(lambda: user.dump_registers(APID, [STATE]))
        self.assertEqual(
            (tx.failure["stage"], tx.failure["code"], tx.failure["data"]),
            (2, FAILURE_UNAVAILABLE, b""),
        )


if __name__ == "__main__":
    unittest.main()
