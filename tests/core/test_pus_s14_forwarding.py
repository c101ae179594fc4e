"""ST[14]: real-time forwarding control, provider against user, and its effect on the TM out."""

import unittest

from obsw.pus.messages import FAILURE_REFUSED, FAILURE_UNKNOWN_ID
from obsw.pus.parameters import ParameterPool
from obsw.pus.services.s03_housekeeping import Housekeeping
from obsw.pus.services.s05_events import EventReporting
from obsw.pus.services.s14_forwarding import ForwardingControl, ForwardingUser
from obsw.pus.services.s17_test import ServiceTest, ServiceTestUser
from obsw.store import Store
from pus_loop import APID, Loop, sdb
from store_sim import SimFs


def make(store=None):
    db = sdb()
    loop = Loop(store=store)
    pool = ParameterPool(db)
    hk = loop.app.register(
        Housekeeping(
            pool,
            [
                {"sid": 1, "interval": 1, "parameters": [1], "enabled": True},
                {"sid": 2, "interval": 1, "parameters": [2], "enabled": True},
            ],
            diagnostic=[
                {"sid": 1, "interval": 1, "parameters": [3], "enabled": True},
                {"sid": 3, "interval": 1, "parameters": [3], "enabled": True},
            ],
        )
    )
    loop.app.register(ServiceTest())
    loop.app.register(EventReporting())
    fwd = loop.app.register(ForwardingControl())
    user = loop.ground.register(ForwardingUser())
    test = loop.ground.register(ServiceTestUser())
    return loop, fwd, user, test, hk


def sids(loop, subtype=25):
    return [
        (t.data[0] << 8) | t.data[1] for t in loop.tm if (t.service, t.subtype) == (3, subtype)
    ]


class TestForwarding(unittest.TestCase):
    def test_everything_of_the_own_apid_goes_out_at_first(self):
        loop, fwd, user, test, hk = make()
        tx = loop.run(user.report_types(APID))
        self.assertEqual(tx.reply, {"types": {APID: {}}})
        loop.app.tick()
        loop.pump()
        self.assertEqual(sorted(sids(loop)), [1, 2])
        self.assertEqual(loop.run(user.report_hk(APID)).reply, {"hk": {APID: []}})

    def test_report_types_select_what_goes_out(self):
        loop, fwd, user, test, hk = make()
        n = len(loop.tm)
        tx = loop.run(user.delete_types(APID, {}))  # nothing forwarded any more
        self.assertFalse(tx.done)  # not even its own completion report came
        tx = loop.run(test.ping(APID))
        self.assertEqual(len(loop.tm), n + 2)  # acceptance and start of the first request
        self.assertFalse(tx.done)
        self.assertEqual(fwd.withheld, 5)
        self.assertEqual(loop.app.counters["completed"], 2)  # the process kept going
        user.add_types(APID, {APID: {1: [], 17: [2]}})
        loop.pump()
        self.assertEqual(loop.types()[-3:], [(1, 1), (1, 3), (1, 7)])
        tx = loop.run(test.ping(APID))
        self.assertTrue(tx.ok)
        self.assertEqual(loop.types()[-2:], [(17, 2), (1, 7)])
        tx = loop.run(user.report_types(APID))
        self.assertEqual(tx.reply, None)  # TM[14,4] itself is not selected
        self.assertTrue(tx.ok)
        self.assertTrue(loop.run(user.add_types(APID, {APID: {14: [4]}})).ok)
        tx = loop.run(user.report_types(APID))
        self.assertEqual(tx.reply, {"types": {APID: {1: [], 14: [4], 17: [2]}}})
        tx = loop.run(user.delete_types(APID, {APID: {1: [7]}}))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)  # service 1 selected as a whole

    def test_delete_refusals(self):
        loop, fwd, user, test, hk = make()
        user.add_types(APID, {APID: {17: [2]}, 33: {5: [1, 2]}})
        loop.pump()
        for sel, code in (
            ({34: {}}, FAILURE_UNKNOWN_ID),
            ({33: {6: []}}, FAILURE_UNKNOWN_ID),
            ({APID: {3: [25]}}, FAILURE_REFUSED),  # APID selected as a whole
        ):
            tx = loop.run(user.delete_types(APID, sel))
            self.assertEqual(tx.failure["code"], code)
        self.assertTrue(loop.run(user.delete_types(APID, {33: {5: [1]}})).ok)
        self.assertTrue(fwd.types.selects(33, 5, 2))
        self.assertFalse(fwd.types.selects(33, 5, 1))
        self.assertTrue(loop.run(user.delete_types(APID, {33: {5: [2]}})).ok)
        self.assertFalse(33 in fwd.types.apids)

    def test_housekeeping_structures(self):
        loop, fwd, user, test, hk = make()
        self.assertTrue(loop.run(user.delete_hk(APID, {APID: []})).ok)
        self.assertTrue(loop.run(user.add_hk(APID, {APID: [2]})).ok)
        self.assertEqual(loop.run(user.report_hk(APID)).reply, {"hk": {APID: [2]}})
        loop.app.tick()
        loop.pump()
        self.assertEqual(sids(loop), [2])
        tx = loop.run(user.delete_hk(APID, {APID: [1]}))
        self.assertEqual(tx.failure["code"], FAILURE_UNKNOWN_ID)
        self.assertTrue(loop.run(user.delete_hk(APID, {})).ok)
        loop.app.tick()
        loop.pump()
        self.assertEqual(sids(loop), [2])

    def test_diagnostic_structures(self):
        loop, fwd, user, test, hk = make()
        loop.app.tick()
        loop.pump()
        self.assertEqual(sorted(sids(loop, 26)), [1, 3])  # every SID of the own APID at first
        self.assertEqual(loop.run(user.report_diag(APID)).reply, {"diag": {APID: []}})
        self.assertEqual(loop.types()[-2], (14, 12))
        self.assertTrue(loop.run(user.delete_diag(APID, {APID: []})).ok)
        self.assertTrue(loop.run(user.add_diag(APID, {APID: [3], 40: [1, 2]})).ok)
        tx = loop.run(user.report_diag(APID))
        self.assertEqual(tx.reply, {"diag": {APID: [3], 40: [1, 2]}})
        n = len(sids(loop, 26))
        loop.app.tick()
        loop.pump()
        self.assertEqual(sids(loop, 26)[n:], [3])
        self.assertEqual(sorted(sids(loop)[-2:]), [1, 2])  # housekeeping SIDs unaffected
        tx = loop.run(user.delete_diag(APID, {APID: [1]}))
        self.assertEqual(tx.failure["code"], FAILURE_UNKNOWN_ID)
        tx = loop.run(user.delete_diag(APID, {41: []}))
        self.assertEqual(tx.failure["code"], FAILURE_UNKNOWN_ID)
        self.assertTrue(loop.run(user.delete_diag(APID, {40: [2]})).ok)
        self.assertEqual(
            fwd.diag.as_list(), [{"apid": APID, "ids": [3]}, {"apid": 40, "ids": [1]}]
        )
        self.assertTrue(loop.run(user.delete_diag(APID, {})).ok)  # N = 0: all
        n = len(sids(loop, 26))
        loop.app.tick()
        loop.pump()
        self.assertEqual(len(sids(loop, 26)), n)

    def test_blocked_events(self):
        loop, fwd, user, test, hk = make()
        self.assertTrue(loop.run(user.add_blocked(APID, {APID: [3, 4]})).ok)
        tx = loop.run(user.report_blocked(APID))
        self.assertEqual(tx.reply, {"blocked": {APID: [3, 4]}})
        for eid in (3, 4, 5):
            loop.app.event(eid, 2)
        loop.pump()
        events = [(t.data[0] << 8) | t.data[1] for t in loop.tm if t.service == 5]
        self.assertEqual(events, [5])
        self.assertTrue(loop.run(user.delete_blocked(APID, {APID: [3]})).ok)
        tx = loop.run(user.delete_blocked(APID, {APID: [3]}))
        self.assertEqual(tx.failure["code"], FAILURE_UNKNOWN_ID)
        loop.app.event(3, 2)
        loop.pump()
        self.assertEqual(loop.tm[-1].service, 5)
        self.assertTrue(loop.run(user.delete_blocked(APID, {})).ok)
        self.assertEqual(fwd.blocked.apids, {})

    def test_configuration_survives_a_restart(self):
        fs = SimFs()
        loop, fwd, user, test, hk = make(Store("/ctx", fs))
        loop.run(user.add_types(APID, {40: {3: [25]}}))
        loop.run(user.add_hk(APID, {40: [7]}))
        loop.run(user.add_blocked(APID, {APID: [9]}))
        loop.run(user.add_diag(APID, {40: [8]}))
        loop2, fwd2, user2, test2, hk2 = make(Store("/ctx", fs))
        self.assertEqual(fwd2.types.as_list(), fwd.types.as_list())
        self.assertEqual(fwd2.hk.as_list(), [{"apid": APID, "ids": []}, {"apid": 40, "ids": [7]}])
        self.assertEqual(fwd2.blocked.pairs(), [{"apid": APID, "id": 9}])
        self.assertEqual(
            fwd2.diag.as_list(), [{"apid": APID, "ids": []}, {"apid": 40, "ids": [8]}]
        )
        fwd2.restore(fwd2.context()[:3])  # a context saved before diagnostic forwarding
        self.assertEqual(len(fwd2.diag.as_list()), 2)


if __name__ == "__main__":
    unittest.main()
