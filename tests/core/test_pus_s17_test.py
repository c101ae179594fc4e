"""ST[17]: are-you-alive and the on-board connection test, provider against user."""

import asyncio
import unittest

from obsw.pus.services.s01_verification import FAILURE_UNKNOWN_ID
from obsw.pus.services.s17_test import ServiceTest, ServiceTestUser
from pus_loop import APID, Loop


def make(peers=None):
    loop = Loop()
    loop.app.register(ServiceTest(peers))
    return loop, loop.ground.register(ServiceTestUser())


class TestService17(unittest.TestCase):
    def test_are_you_alive(self):
        loop, user = make()
        tx = loop.run(user.ping(APID))
        self.assertTrue(tx.ok)
        self.assertEqual(tx.reply, {"alive": True})
        self.assertEqual(loop.tm[2].data, b"")

    def test_connection_to_itself(self):
        loop, user = make()
        tx = loop.run(user.connection_test(APID, APID))
        self.assertTrue(tx.ok)
        self.assertEqual(tx.reply, {"apid": APID})
        self.assertEqual(loop.types(), [(1, 1), (1, 3), (17, 4), (1, 7)])

    def test_connection_to_a_peer(self):
        loop, user = make({11: lambda apid: True, 12: lambda apid: False})
        tx = loop.run(user.connection_test(APID, 11))
        self.assertEqual(tx.reply, {"apid": 11})
        tx = loop.run(user.connection_test(APID, 12))
        self.assertEqual(tx.failure["code"], FAILURE_UNKNOWN_ID)
        self.assertEqual(tx.failure["stage"], 4)

    def test_connection_to_an_async_peer(self):
        async def probe(apid):
            await asyncio.sleep(0)
            return True

        loop, user = make({11: probe})
        tx = loop.run_async(lambda: user.connection_test(APID, 11))
        self.assertTrue(tx.ok)
        self.assertEqual(tx.reply, {"apid": 11})

    def test_unknown_process(self):
        loop, user = make()
        tx = loop.run(user.connection_test(APID, 99))
        self.assertFalse(tx.ok)
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, FAILURE_UNKNOWN_ID))
        self.assertEqual(tx.failure["data"], b"\x00\x63")


if __name__ == "__main__":
    unittest.main()
