"""ST[02]: raw commands to SpaceCAN equipment and their replies through the DeviceAccess
component, provider against user; silence, rejections and unknown devices."""

import unittest

from obsw.il.node import Node
from obsw.pus.messages import FAILURE_COMPONENT, FAILURE_TIMEOUT, FAILURE_UNKNOWN_ID
from obsw.pus.services.s02_device_access import DeviceAccess, DeviceUser
from obsw.spacecan.controller import Controller
from obsw.spacecan.device_access import DEVICE_ACCESS, SpaceCanDeviceAccess
from obsw.spacecan.nodedef import NodeDefinition
from obsw.spacecan.responder import Responder
from obsw.spacecan.sim import SimNetwork
from pus_loop import APID, Loop, asyncio

NODE = {
    "parameters": [{"parameter_id": 1, "parameter_name": "mode", "encoding": "u8", "value": 3}],
    "housekeeping_reports": [],
    "functions": [{"function_id": 2, "function_name": "reset"}],
}
RAW = 5  # a node in raw data mode
PACKETS = 6  # a node speaking SpaceCAN service packets
SILENT = 7  # a raw node that never answers


class Bench:
    def __init__(self, devices=None):
        nd = NodeDefinition.from_dict(NODE)
        self.controller = Controller(timeout=0.3, retries=0)
        self.controller.add_node(PACKETS, nd)
        self.access = SpaceCanDeviceAccess(self.controller, (RAW, SILENT), timeout=0.5)
        self.raw = Responder(RAW, nd, use_packets=False)
        self.raw_got = []
        self.raw.on_raw = self._raw
        self.packets = Responder(PACKETS, NodeDefinition.from_dict(NODE))
        self.net = SimNetwork().attach(self.access, self.raw, self.packets)
        self.loop = Loop()
        self.node = Node("obc", clock=self.loop.clock)
        self.node.provide(DEVICE_ACCESS, self.access)
        self.loop.app.register(DeviceAccess(self.node, devices, timeout=2.0))
        self.user = self.loop.ground.register(DeviceUser())

    def _raw(self, data, bus):
        self.raw_got.append(data)
        if data[:1] == b"?":
            self.raw.send_raw(b"R" + data[1:])

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


class TestDeviceAccess(unittest.TestCase):
    def test_physical_commands_go_out_raw(self):
        b = Bench()
        tx = b.run(lambda: b.user.command(APID, [(RAW, b"\x01\x02"), (RAW, bytes(range(10)))]))
        self.assertTrue(tx.ok)
        self.assertEqual(b.raw_got, [b"\x01\x02", bytes(range(8)), b"\x08\x09"])

    def test_physical_acquisition_returns_the_replies(self):
        b = Bench()
        tx = b.run(lambda: b.user.acquire(APID, [(RAW, b"?a"), (RAW, b"?bc")]))
        self.assertTrue(tx.ok)
        self.assertEqual(tx.reply, {"items": [(RAW, b"Ra"), (RAW, b"Rbc")]})
        self.assertEqual(b.loop.types()[-2:], [(2, 9), (1, 7)])

    def test_a_silent_device_times_out(self):
        b = Bench()
        tx = b.run(lambda: b.user.acquire(APID, [(SILENT, b"?")]))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (4, FAILURE_TIMEOUT))
        self.assertEqual(tx.failure["data"], b"\x00\x07")

    def test_logical_commands_and_acquisition(self):
        b = Bench()
        tx = b.run(lambda: b.user.logical_command(APID, [(PACKETS, 8, 1, b"\x02")]))
        self.assertTrue(tx.ok)
        tx = b.run(lambda: b.user.logical_acquire(APID, [(PACKETS, 20, 1, b"\x01\x01")]))
        self.assertTrue(tx.ok)
        ((dev, service, subtype, data),) = tx.reply["items"]
        self.assertEqual((dev, service, subtype), (PACKETS, 20, 2))
        self.assertEqual(data[-1:], b"\x03")  # mode = 3
        tx = b.run(lambda: b.user.logical_acquire(APID, [(PACKETS, 17, 1, b"")]))
        self.assertEqual(tx.reply["items"], [(PACKETS, 17, 2, b"")])

    def test_refusals(self):
        b = Bench()
        tx = b.run(lambda: b.user.logical_command(APID, [(PACKETS, 99, 1, b"")]))
        self.assertEqual(
            (tx.failure["code"], tx.failure["data"]), (FAILURE_COMPONENT, b"\x00\x06")
        )
        tx = b.run(lambda: b.user.command(APID, [(PACKETS, b"x")]))  # not in raw data mode
        self.assertEqual(tx.failure["code"], FAILURE_COMPONENT)
        tx = b.run(lambda: b.user.command(APID, [(500, b"x")]))
        self.assertEqual(tx.failure["code"], FAILURE_COMPONENT)
        b2 = Bench(devices={RAW: "eps"})
        tx = b2.run(lambda: b2.user.command(APID, [(PACKETS, b"x")]))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, FAILURE_UNKNOWN_ID))


if __name__ == "__main__":
    unittest.main()
